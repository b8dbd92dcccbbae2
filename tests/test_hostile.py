"""Hostile input, property-based: malformed models at mbd2d.load / from_dict and the builder
API, NaN, infinities and wrong shapes at the private _core functions.

The contract under test: every malformed input ends in a typed mbd2d error whose message names
the entry (ModelError for bad input, an AnalysisError subclass for numerical outcomes); none
ends in a crash, a Fortran runtime error, a hang, a raw Python exception or NaN output.

How it is tested. A crash (segfault, Fortran runtime error) would kill the pytest process and a
hang would stall it, so every case runs in a worker process: a child Python that imports this
very file and answers calls over a pipe. The test (in the pytest process) draws the hostile
input with hypothesis, sends it to the worker, and fails with the right words when the worker
dies (crash: exit code or signal, and the tail of its stderr), stays silent past HANG_SECONDS
(hang: it is killed and restarted), or reports an assertion or an unexpected exception (its
traceback). The property checks themselves run inside the worker (the ``check_*`` functions).

Hypothesis runs derandomized (reproducible in CI) without an example database. Tests whose
cases reach the core's time loop or its tables (where a case can hang or crash) skip the
shrink phase, so a failure costs one timeout, not hundreds; their failing example is reported
as drawn. A fixed list of named cases (test_named_malformed_models) covers each kind of
malformed model the issue lists, deterministically.

``pytest -s tests/test_hostile.py`` prints how many hostile cases each test ran.
"""
from __future__ import annotations

import atexit
import math
import os
import pickle
import re
import select
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import tomllib
import warnings
from decimal import Decimal
from fractions import Fraction
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, note, settings
from hypothesis import strategies as st

import mbd2d
from mbd2d import _core
from mbd2d.binding.pack import pack
from mbd2d.description.joints import joint_keys
from mbd2d.model import from_dict

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"

#: A case (a model of at most a few bodies, 2 output steps) that has not answered after this
#: long is a hang. Normal cases take milliseconds.
HANG_SECONDS = 10.0
#: The worker's first answer includes importing mbd2d (an editable install may rebuild).
START_SECONDS = 180.0

# ------------------------------------------------------------------------------------------
# case counting (printed at module teardown)
# ------------------------------------------------------------------------------------------
COUNTS: dict[str, int] = {}


def _count(test: str) -> None:
    COUNTS[test] = COUNTS.get(test, 0) + 1


def fuzz_examples(n: int) -> int:
    """The example count of a property test: n in the suite, or MBD2D_FUZZ_EXAMPLES when that
    is larger (a long fuzzing run: ``MBD2D_FUZZ_EXAMPLES=20000 pytest tests/test_hostile.py
    tests/test_fuzz_analyses.py``)."""
    try:
        more = int(os.environ.get("MBD2D_FUZZ_EXAMPLES", "0"))
    except ValueError:
        more = 0
    return max(n, more)


def hostile_settings(n: int, shrink: bool = False) -> settings:
    """Deterministic settings: derandomized, no database, no deadline (timing is the worker's
    job). Without shrink (tests whose cases may hang), the first failing case is reported as
    drawn, so a hang costs one timeout rather than hundreds."""
    phases = [Phase.explicit, Phase.generate] + ([Phase.shrink] if shrink else [])
    return settings(max_examples=fuzz_examples(n), deadline=None, derandomize=True, database=None,
                    phases=phases, print_blob=False, report_multiple_bugs=shrink,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.filter_too_much,
                                           HealthCheck.large_base_example])


# ------------------------------------------------------------------------------------------
# the worker process
# ------------------------------------------------------------------------------------------
_WORKER_MAIN = r"""
import importlib.util, os, sys
chan = os.fdopen(os.dup(1), "wb")
os.dup2(2, 1)              # stray output (Fortran unit 6 too) goes to stderr, not the channel
sys.stdout = sys.stderr
sys.path.insert(0, os.path.dirname(sys.argv[1]))   # the test file's neighbours import
spec = importlib.util.spec_from_file_location(sys.argv[2], sys.argv[1])
mod = importlib.util.module_from_spec(spec)
sys.modules[sys.argv[2]] = mod         # values pickled by the test resolve to this module
spec.loader.exec_module(mod)
mod._worker_loop(sys.stdin.buffer, chan)
"""


def _worker_loop(inp: Any, out: Any, namespace: dict[str, Any] | None = None) -> None:
    """Worker side: read (function name, args), run it (a function of ``namespace``, this
    module's by default), answer ("ok", value) or ("raised", traceback text). Never dies on
    an exception; only a crash or a hang stops it."""
    import traceback
    calls = globals() if namespace is None else namespace
    warnings.simplefilter("error")     # as pytest's filterwarnings = error
    while True:
        head = inp.read(8)
        if len(head) < 8:
            return
        (n,) = struct.unpack("<Q", head)
        name, args = pickle.loads(inp.read(n))
        try:
            reply: tuple[str, Any] = ("ok", calls[name](*args))
        except BaseException as exc:  # noqa: BLE001 - relayed to the test as a failure
            reply = ("raised", "".join(traceback.format_exception(exc)))
        try:
            data = pickle.dumps(reply)
        except Exception as exc:  # noqa: BLE001
            data = pickle.dumps(("raised", f"unpicklable answer: {exc!r}"))
        out.write(struct.pack("<Q", len(data)) + data)
        out.flush()


def ping() -> int:
    """Answered once the worker has imported everything."""
    return os.getpid()


def _read_exact(fd: int, n: int) -> bytes:
    buf = b""
    while len(buf) < n:
        chunk = os.read(fd, n - len(buf))
        if not chunk:
            break
        buf += chunk
    return buf


class _Fatal(Exception):
    """The worker crashed or hung."""


class Worker:
    """The pytest side of the worker: call, detect crashes and hangs, restart. The worker
    imports ``path`` (this file by default), whose functions it runs."""

    def __init__(self, path: Path | None = None) -> None:
        self.path = Path(__file__) if path is None else Path(path)
        self.proc: subprocess.Popen[bytes] | None = None
        self.err: Any = None
        self.fatal: dict[bytes, str] = {}
        self.tmp: str | None = None

    def start(self) -> None:
        self.err = tempfile.TemporaryFile()
        if self.tmp is None:          # model files the worker writes; removed in stop()
            self.tmp = tempfile.mkdtemp(prefix="mbd2d-hostile-")
        env = dict(os.environ, PYTHONFAULTHANDLER="1", OMP_NUM_THREADS="1",
                   OPENBLAS_NUM_THREADS="1", MBD2D_HOSTILE_TMP=self.tmp)
        # the interpreter's own flags (-S, -I, -X ...) as multiprocessing passes them on
        flags = subprocess._args_from_interpreter_flags()  # type: ignore[attr-defined]
        self.proc = subprocess.Popen([sys.executable, *flags, "-c", _WORKER_MAIN,
                                      str(self.path), self.path.stem],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=self.err, cwd=str(ROOT), env=env, bufsize=0)

    def stop(self) -> None:
        if self.proc is not None:
            try:
                self.proc.stdin.close()  # type: ignore[union-attr]
                self.proc.wait(timeout=10)
            except Exception:  # noqa: BLE001
                self.kill()
            self._release()
        if self.tmp is not None:
            shutil.rmtree(self.tmp, ignore_errors=True)
            self.tmp = None

    def kill(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()          # our own child, by its handle
            self.proc.wait()
        self._release()

    def _release(self) -> None:
        """Close the pipes and the stderr file of a finished worker."""
        if self.proc is not None:
            for f in (self.proc.stdin, self.proc.stdout):
                try:
                    f.close()  # type: ignore[union-attr]
                except Exception:  # noqa: BLE001
                    pass
        if self.err is not None:
            self.err.close()
            self.err = None
        self.proc = None

    def _stderr_tail(self) -> str:
        try:
            self.err.seek(0)
            text = self.err.read().decode("utf-8", "replace")
        except Exception:  # noqa: BLE001
            return "(stderr unavailable)"
        return text[-3000:].strip() or "(empty)"

    def call(self, name: str, *args: Any, limit: float = HANG_SECONDS) -> Any:
        """Run check function `name` in the worker; fail the test on crash, hang (no answer
        within ``limit`` seconds) or a raised exception (with its traceback). A case that crashed or hung is not run again when
        hypothesis replays it to report it (the engine is deterministic): the same failure
        is raised at once."""
        __tracebackhide__ = True
        key = pickle.dumps((name, args))
        if key in self.fatal:
            raise AssertionError(self.fatal[key])
        if self.proc is None or self.proc.poll() is not None:
            self.start()
            self._call("ping", START_SECONDS)        # import time is not the case's time
        try:
            return self._call(name, limit, *args)
        except _Fatal as exc:
            self.fatal[key] = str(exc)
            raise AssertionError(str(exc)) from None

    def _call(self, name: str, limit: float, *args: Any) -> Any:
        __tracebackhide__ = True
        assert self.proc is not None
        data = pickle.dumps((name, args))
        try:
            self.proc.stdin.write(struct.pack("<Q", len(data)) + data)  # type: ignore
            self.proc.stdin.flush()  # type: ignore[union-attr]
        except BrokenPipeError:
            pass                      # it died: reported below
        fd = self.proc.stdout.fileno()  # type: ignore[union-attr]
        ready, _, _ = select.select([fd], [], [], limit)
        if not ready:
            self.kill()
            raise _Fatal(f"HANG: {name} gave no answer within {limit:g} s (worker killed)")
        head = _read_exact(fd, 8)
        if len(head) < 8:
            rc = self.proc.wait()
            tail = self._stderr_tail()
            self._release()
            if rc < 0:
                try:
                    what = f"signal {signal.Signals(-rc).name}"
                except ValueError:
                    what = f"signal {-rc}"
            else:
                what = f"exit code {rc}" + (" (a Fortran runtime error exits with 2)"
                                            if rc == 2 else "")
            raise _Fatal(f"CRASH: the worker died ({what}) in {name}; "
                         f"its stderr ends with:\n{tail}")
        (n,) = struct.unpack("<Q", head)
        kind, value = pickle.loads(_read_exact(fd, n))
        if kind == "raised":
            raise AssertionError(f"{name} failed in the worker:\n{value}")
        return value


WORKER = Worker()
atexit.register(WORKER.stop)


@pytest.fixture(scope="module", autouse=True)
def _hostile_summary():
    """Print the number of hostile cases per test, then stop the worker."""
    yield
    WORKER.stop()
    total = 0
    print()
    for test, n in COUNTS.items():
        print(f"hostile cases run: {n:5d}  {test}")
        total += n
    print(f"hostile cases run: {total:5d}  in total")


# ------------------------------------------------------------------------------------------
# base models
# ------------------------------------------------------------------------------------------
EXAMPLE_FILES = ["fourbar_grashof.toml", "slider_crank.toml", "cam_follower.toml",
                 "door_two_hinges.toml", "fourbar_seed.toml", "parallelogram_extra_link.toml"]

# small valid models covering every joint type, both follower forms and every driver type
EXTRA_TOML = {
    "yoke": """
[model]
name = "yoke"
[[body]]
name = "crank"
q0 = [0.4, 0.0, 0.0]
[[body]]
name = "yoke"
q0 = [0.8, 0.0, 0.0]
[[joint]]
name = "O"
type = "revolute"
bodies = ["ground", "crank"]
points = [[0, 0], [-0.4, 0]]
[[joint]]
name = "guide"
type = "translational"
bodies = ["ground", "yoke"]
points = [[0, 0], [0, 0]]
axes = [[1, 0], [1, 0]]
[[joint]]
name = "slot"
type = "revolute-translational"
bodies = ["yoke", "crank"]
points = [[0, 0], [0.4, 0]]
axis = [0, 1]
offset = 0.0
[[driver]]
name = "motor"
type = "absolute"
body = "crank"
coordinate = "theta"
f = { poly = [0, 6.283185307179586] }
""",
    "rail": """
[[body]]
name = "crank"
q0 = [0.5, 0.0, 0.0]
[[body]]
name = "rod"
q0 = [2.5, 0.25, 0.17]
[[joint]]
type = "revolute"
bodies = ["ground", "crank"]
points = [[0, 0], [-0.5, 0]]
[[joint]]
type = "revolute"
bodies = ["crank", "rod"]
points = [[0.5, 0], [-1.5, 0]]
[[joint]]
name = "rail"
type = "point-on-line"
bodies = ["ground", "rod"]
points = [[0, 0.5], [1.5, 0]]
axis = [1, 0]
[[driver]]
type = "absolute"
body = "crank"
coordinate = "theta"
f = { poly = [0, 6.283185307179586] }
""",
    "weld_slot": """
[[body]]
name = "crank"
q0 = [0.5, 0.0, 0.0]
[[body]]
name = "plate"
q0 = [1.0, 0.2, 0.3]
[[body]]
name = "pin"
q0 = [0.0, 2.0, 0.0]
[[joint]]
name = "O"
type = "revolute"
bodies = ["ground", "crank"]
points = [[0, 0], [-0.5, 0]]
[[joint]]
name = "w"
type = "weld"
bodies = ["crank", "plate"]
points = [[0.5, 0], [0, -0.2]]
angle = 0.3
[[joint]]
name = "slot"
type = "point-on-curve"
bodies = ["ground", "pin"]
curve = { circle = { center = [0, 0], radius = 2.0 } }
point = [0, 0]
[[joint]]
name = "fix"
type = "absolute"
body = "pin"
coordinate = "theta"
value = 0.0
[[driver]]
name = "motor"
type = "absolute"
body = "crank"
coordinate = "theta"
f = { poly = [0, 6.283185307179586] }
[[driver]]
name = "push"
type = "absolute"
body = "pin"
coordinate = "x"
f = { harmonic = [{ amplitude = 1.5, omega = 6.283185307179586, phase = 0.0 }] }
""",
    "gears": """
[[body]]
name = "carrier"
q0 = [0.5, 0, 0]
[[body]]
name = "planet"
q0 = [1.0, 0, 0]
[[body]]
name = "ring"
q0 = [0, 0, 0]
[[body]]
name = "wheel"
q0 = [0, 3, 0.4]
[[joint]]
name = "C"
type = "revolute"
bodies = ["ground", "carrier"]
points = [[0, 0], [-0.5, 0]]
[[joint]]
name = "P"
type = "revolute"
bodies = ["carrier", "planet"]
points = [[0.5, 0], [0, 0]]
[[joint]]
name = "R"
type = "weld"
bodies = ["ground", "ring"]
points = [[0, 0], [0, 0]]
[[joint]]
name = "mesh"
type = "gear"
bodies = ["planet", "ring"]
radii = [0.5, 1.5]
internal = true
carrier = "carrier"
[[joint]]
name = "W"
type = "revolute"
bodies = ["ground", "wheel"]
points = [[0, 3], [0, 0]]
[[joint]]
name = "mesh2"
type = "gear"
bodies = ["carrier", "wheel"]
radii = [1.0, 2.0]
phase = 0.8
[[driver]]
name = "motor"
type = "absolute"
body = "carrier"
coordinate = "theta"
f = { poly = [0, 6.283185307179586] }
""",
    "rolling": """
[[body]]
name = "pinion"
q0 = [0, 0, 0]
[[body]]
name = "rack"
q0 = [0, -0.3, 0]
[[body]]
name = "disc"
q0 = [0, 0.3, 0]
[[joint]]
name = "O"
type = "revolute"
bodies = ["ground", "pinion"]
points = [[0, 0], [0, 0]]
[[joint]]
name = "guide"
type = "translational"
bodies = ["ground", "rack"]
points = [[0, -0.3], [0, 0]]
axes = [[1, 0], [1, 0]]
[[joint]]
name = "rp"
type = "rack-pinion"
bodies = ["pinion", "rack"]
center = [0, 0]
point = [0, 0]
axis = [1, 0]
radius = 0.3
[[joint]]
name = "roll"
type = "rolling-disc"
bodies = ["disc", "ground"]
center = [0, 0]
point = [0, 0]
axis = [1, 0]
radius = 0.25
phase = 0.0
[[driver]]
name = "spin"
type = "relative-angle"
bodies = ["ground", "pinion"]
f = { poly = [0, 6.283185307179586] }
[[driver]]
name = "push"
type = "absolute"
body = "disc"
coordinate = "x"
f = { poly = [0, 0.5, 0.2] }
""",
    "slide": """
[[body]]
name = "slider"
q0 = [0.2, 0.0, 0.0]
[[body]]
name = "arm"
q0 = [0.0, 1.0, 0.0]
[[joint]]
name = "guide"
type = "translational"
bodies = ["ground", "slider"]
points = [[0, 0], [0, 0]]
axes = [[1, 0], [1, 0]]
[[joint]]
name = "hinge"
type = "revolute"
bodies = ["ground", "arm"]
points = [[0, 1], [0, 0]]
[[joint]]
name = "tie"
type = "distance"
bodies = ["arm", "ground"]
points = [[0.5, 0], [0.5, 2.0]]
distance = 1.0
[[driver]]
name = "stroke"
type = "relative-distance"
joint = "guide"
f = { poly = [0.2, 0.3] }
""",
    "fourier_cam": """
[[body]]
name = "cam"
q0 = [0.0, 0.0, 0.0]
[[body]]
name = "follower"
q0 = [0.0, 1.3, 0.0]
[[joint]]
name = "pivot"
type = "revolute"
bodies = ["ground", "cam"]
points = [[0.0, 0.0], [0.0, 0.0]]
[[joint]]
name = "guide"
type = "translational"
bodies = ["ground", "follower"]
points = [[0.0, 0.0], [0.0, 0.0]]
axes = [[0.0, 1.0], [0.0, 1.0]]
[[joint]]
name = "contact"
type = "cam"
bodies = ["cam", "follower"]
profile = { fourier = { center = [0.0, 0.0], a = [1.0, 0.1, 0.05], b = [0.1, 0.0] } }
follower = { flat = { point = [0.0, 0.0], normal = [0.0, -1.0] } }
[[driver]]
name = "motor"
type = "absolute"
body = "cam"
coordinate = "theta"
f = { poly = [0.0, 6.283185307179586] }
""",
    "spline_cam": """
[[body]]
name = "cam"
q0 = [0.0, 0.0, 0.0]
[[body]]
name = "follower"
q0 = [0.0, 1.0, 0.0]
[[joint]]
name = "pivot"
type = "revolute"
bodies = ["ground", "cam"]
points = [[0.0, 0.0], [0.0, 0.0]]
[[joint]]
name = "guide"
type = "translational"
bodies = ["ground", "follower"]
points = [[0.0, 0.0], [0.0, 0.0]]
axes = [[0.0, 1.0], [0.0, 1.0]]
[[joint]]
name = "contact"
type = "cam"
bodies = ["cam", "follower"]
profile = { spline = { points = [[1.0, 0.0], [0.7, 0.7], [0.0, 0.9], [-0.7, 0.7], [-1.0, 0.0], [-0.7, -0.7], [0.0, -1.1], [0.7, -0.7]] } }
follower = { point = [0.0, 0.0] }
[[driver]]
name = "motor"
type = "absolute"
body = "cam"
coordinate = "theta"
f = { poly = [0.0, 6.283185307179586] }
""",
}

BASE_TEXT: dict[str, str] = {p: (EXAMPLES / p).read_text(encoding="utf-8")
                             for p in EXAMPLE_FILES}
BASE_TEXT.update(EXTRA_TOML)
BASE: dict[str, dict[str, Any]] = {k: tomllib.loads(v) for k, v in BASE_TEXT.items()}
BASE_NAMES = sorted(BASE)

SECTIONS = ("body", "joint", "driver", "force")
JOINT_TYPES = sorted(joint_keys())
DRIVER_TYPES = ["absolute", "relative-angle", "relative-distance"]
ALL_KEYS = sorted({k for a, _ in joint_keys().values() for k in a}
                  | {"name", "type", "q0", "mass", "inertia", "v0", "body", "coordinate",
                     "bodies", "joint", "f", "gravity", "poly", "harmonic", "amplitude",
                     "omega", "phase", "circle", "spline", "fourier", "center", "radius",
                     "a", "b", "roller", "flat", "normal"})

# ------------------------------------------------------------------------------------------
# checks (run in the worker)
# ------------------------------------------------------------------------------------------
ALLOWED_WARNINGS = (mbd2d.RedundantConstraintWarning, mbd2d.SingularPassageWarning,
                    mbd2d.LiftOffWarning)   # a cam that must pull its follower: a report
AUTO_NAME = re.compile(r"(joint|driver|force|contact)\d+")
FIXED_ENTRIES = {"[model]", "model", "analysis", "state", "<dict>", "<string>", "stepping",
                 "dynamics", "statics", "linearized system", "frequency response"}


def assert_names_entry(err: BaseException, names: set[str], bounds: dict[str, int]) -> None:
    """A ModelError whose message starts with the entry it names, and that entry exists:
    a section entry "[[joint]] #k" with k within the input, "joint 'NAME' (type)" with a
    NAME from the input (or a generated one such as 'joint3'), "driver #k", "[model]",
    "model 'NAME'", the file or string source, "analysis" or "state"."""
    assert isinstance(err, mbd2d.ModelError) and isinstance(err, ValueError), repr(err)
    msg, entry = str(err), err.entry
    assert isinstance(entry, str) and entry.strip(), f"ModelError names no entry: {msg!r}"
    assert msg.startswith(entry + ": ") and msg[len(entry) + 2:].strip(), \
        f"message does not lead with its entry: {msg!r}"
    if entry in FIXED_ENTRIES or entry.startswith("model ") or entry.endswith(".toml"):
        return
    # a design parameter the analysis refuses as an input: KIND.NAME.path or model.gravity.k
    p = re.fullmatch(r"(body|joint|driver|force|contact)\.([^.]+)\..+", entry)
    if p or re.fullmatch(r"model\.gravity\.[01]", entry):
        assert not p or p.group(2) in names or AUTO_NAME.fullmatch(p.group(2)), \
            f"{entry!r} names a parameter of an entry not in the input: {msg!r}"
        return
    m = re.match(r"\[\[(body|joint|driver|force)\]\] #(\d+)(?: |$)", entry) \
        or re.match(r"(body|joint|driver|force) #(\d+)(?: |$)", entry)
    if m:
        k = int(m.group(2))
        assert 1 <= k <= bounds.get(m.group(1), 0), \
            f"{entry!r} points past the {bounds.get(m.group(1), 0)} {m.group(1)} entries: {msg!r}"
        return
    m = re.match(r"(body|joint|driver|force) (.+)$", entry, flags=re.S)
    assert m, f"message names no recognisable entry: {msg!r}"
    rest = m.group(2)
    if any(rest.startswith(repr(n)) for n in names):
        return
    g = re.match(r"'([a-z_]+\d+)'", rest)
    assert g and AUTO_NAME.fullmatch(g.group(1)), \
        f"{entry!r} names an entry that is not in the input (names {sorted(names)}): {msg!r}"


def _no_nan(what: str, *arrays: Any) -> None:
    for a in arrays:
        a = np.asarray(a, dtype=float)
        assert not np.isnan(a).any(), f"NaN in {what}"


def _finite(what: str, *arrays: Any) -> None:
    for a in arrays:
        a = np.asarray(a, dtype=float)
        assert np.isfinite(a).all(), f"non-finite values in {what}: {a!r}"


def _analysis_error(err: mbd2d.AnalysisError, what: str) -> None:
    assert str(err).strip(), f"{type(err).__name__} with an empty message in {what}"
    res = err.results
    if res is not None:
        # (a positions-only run has no velocities, accelerations)
        _finite(f"the partial results of {type(err).__name__} from {what} ({str(err)[:200]})",
                res.t, res.q, *(x for x in (res.qd, res.qdd) if x is not None))


def _memory_error(err: mbd2d.InsufficientMemoryError, what: str) -> None:
    """A refusal for memory says how much and what to change."""
    text = str(err)
    assert isinstance(err, MemoryError) and "every=" in text and "banded" in text, \
        f"InsufficientMemoryError from {what} without the size or the advice: {text!r}"


def exercise(model: mbd2d.Model, names: set[str], bounds: dict[str, int]) -> tuple[str, ...]:
    """What a user does next with a model that built: counts, a short kinematic run (t_end
    0.1 s, 2 steps), the DOF report, Phi, J, nu and gamma at the estimates. Each step succeeds
    with finite outputs (no NaN for Phi and the rest), or raises a typed error: a ModelError
    naming its entry, or an AnalysisError whose partial results hold no NaN. Anything else
    escapes and fails the case, CoreError included (the core's internal error, a bug by its
    own definition). Only RedundantConstraintWarning and SingularPassageWarning may be
    emitted. Returns the outcome of each step."""
    out: list[str] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            neq, nq = model.counts()
        except mbd2d.ModelError as exc:
            assert_names_entry(exc, names, bounds)
            out.append("counts:ModelError")
            return tuple(out)
        nb = len(model.bodies)
        assert isinstance(neq, int) and isinstance(nq, int)
        assert nq >= 3 * nb and neq >= 1, (neq, nq, nb)
        out.append("counts:ok")
        try:
            res = model.kinematics(t_end=0.1, steps=2)
        except mbd2d.ModelError as exc:
            assert_names_entry(exc, names, bounds)
            out.append("kinematics:ModelError")
        except mbd2d.AnalysisError as exc:
            _analysis_error(exc, "kinematics")
            out.append(f"kinematics:{type(exc).__name__}")
        except mbd2d.InsufficientMemoryError as exc:
            _memory_error(exc, "kinematics")
            out.append("kinematics:InsufficientMemoryError")
        else:
            assert res.q.shape == (3, nq), res.q.shape
            _finite("kinematics results", res.t, res.q, res.qd, res.qdd)
            out.append("kinematics:ok")
        try:
            rep = model.analyze_dof()
        except mbd2d.ModelError as exc:
            assert_names_entry(exc, names, bounds)
            out.append("dof:ModelError")
        except mbd2d.AnalysisError as exc:
            _analysis_error(exc, "analyze_dof")
            out.append(f"dof:{type(exc).__name__}")
        else:
            _finite("the DOF report's configuration", rep.q)
            assert 0 <= rep.rank <= min(nq, neq), rep
            out.append("dof:ok")
        q = np.zeros(nq)
        q[:3 * nb] = np.array([b.q0 for b in model.bodies]).ravel()
        try:
            _finite("Phi, J, nu, gamma at the q0 estimates", model.phi(q), model.jacobian(q),
                    model.nu(q), model.gamma(q, np.zeros(nq)))
        except mbd2d.ModelError as exc:
            assert_names_entry(exc, names, bounds)
            out.append("eval:ModelError")
    bad = [f"{w.category.__name__}: {w.message}" for w in caught
           if not issubclass(w.category, ALLOWED_WARNINGS)]
    assert not bad, f"unexpected warnings: {bad}"
    return tuple(out)


def _data_names(data: Any) -> tuple[set[str], dict[str, int]]:
    """Names given in (possibly malformed) model data, and the entry count per section."""
    names: set[str] = set()
    bounds: dict[str, int] = {}
    if not isinstance(data, dict):
        return names, bounds
    for sec in SECTIONS:
        entries = data.get(sec)
        bounds[sec] = len(entries) if isinstance(entries, list) else 0
        for e in entries if isinstance(entries, list) else []:
            if isinstance(e, dict) and isinstance(e.get("name"), str):
                names.add(e["name"])
    return names, bounds


def _build_outcome(build: Callable[[], mbd2d.Model], names: set[str],
                   bounds: dict[str, int]) -> tuple[str, ...]:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            model = build()
    except mbd2d.ModelError as exc:
        assert_names_entry(exc, names, bounds)
        return ("build:ModelError",)
    assert isinstance(model, mbd2d.Model)
    return ("build:ok",) + exercise(model, names, bounds)


def _tmpdir() -> Path:
    """The directory the test gave the worker for model files."""
    return Path(os.environ["MBD2D_HOSTILE_TMP"])


def check_model_data(data: Any, text: str | None) -> tuple[str, ...]:
    """A mutated model through from_dict and, when it has a TOML form, through mbd2d.load
    from a file: the same outcome both ways, each a typed error or a working model."""
    names, bounds = _data_names(data)
    out = _build_outcome(lambda: from_dict(data), names, bounds)
    if text is not None:
        path = _tmpdir() / "model.toml"
        path.write_text(text, encoding="utf-8")
        out_file = _build_outcome(lambda: mbd2d.load(path), names, bounds)
        assert out_file == out, f"from_dict gave {out}, load(file) gave {out_file}"
    return out


def check_model_text(text: str | bytes) -> tuple[str, ...]:
    """Damaged TOML text (or bytes) through mbd2d.loads and mbd2d.load."""
    path = _tmpdir() / "damaged.toml"
    if isinstance(text, bytes):
        path.write_bytes(text)
        try:
            data = tomllib.loads(text.decode("utf-8"))
        except (UnicodeDecodeError, tomllib.TOMLDecodeError):
            data = None
        return _build_outcome(lambda: mbd2d.load(path), *_data_names(data))
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        data = None
    names, bounds = _data_names(data)
    out = _build_outcome(lambda: mbd2d.loads(text), names, bounds)
    try:
        path.write_text(text, encoding="utf-8")
    except UnicodeEncodeError:
        return out
    out_file = _build_outcome(lambda: mbd2d.load(path), names, bounds)
    assert out_file == out, f"loads gave {out}, load(file) gave {out_file}"
    return out


BUILDER_BODIES = [("crank", [0.5, 0.0, 0.0]), ("rod", [2.5, 0.25, 0.17]),
                  ("slider", [3.96, 0.5, 0.0])]


def check_builder(gravity: Any, calls: list[tuple[str, dict[str, Any]]]) -> tuple[str, ...]:
    """A sequence of builder calls with hostile arguments: each call adds its entry or raises
    a ModelError naming it and leaves the model as it was; the model then behaves (see
    exercise)."""
    names = {"hostile"} | {n for n, _ in BUILDER_BODIES} | \
        {kw["name"] for _, kw in calls if isinstance(kw.get("name"), str)}
    bounds = {"body": len(BUILDER_BODIES) + sum(m == "add_body" for m, _ in calls),
              "joint": sum(m not in ("add_body", "add_driver") for m, _ in calls),
              "driver": sum(m == "add_driver" for m, _ in calls)}
    out: list[str] = []
    try:
        model = mbd2d.Model("hostile", gravity)
    except mbd2d.ModelError as exc:
        assert_names_entry(exc, names, bounds)
        return ("model:ModelError",)
    for name, q0 in BUILDER_BODIES:
        model.add_body(name, q0)
    for method, kw in calls:
        before = (list(model.bodies), list(model.joints), list(model.drivers))
        try:
            getattr(model, method)(**kw)
        except mbd2d.ModelError as exc:
            assert_names_entry(exc, names, bounds)
            after = (model.bodies, model.joints, model.drivers)
            assert all(len(a) == len(b) for a, b in zip(after, before)), \
                f"{method} raised ModelError but left a partial entry: {exc}"
            out.append(f"{method}:ModelError")
        else:
            out.append(f"{method}:ok")
    return tuple(out) + exercise(model, names, bounds)


def cam_base(kind: str) -> mbd2d.Model:
    m = mbd2d.Model("cam-base")
    m.add_body("cam", [0.0, 0.0, 0.0])
    m.add_body("follower", [0.0, 1.2, 0.0])
    m.add_revolute(["ground", "cam"], [[0, 0], [0, 0]], name="pivot")
    m.add_translational(["ground", "follower"], [[0, 0], [0, 0]], [[0, 1], [0, 1]],
                        name="guide")
    if kind == "point-on-curve":
        m.add_driver("absolute", body="cam", coordinate="theta", f={"poly": [0.0, 1.0]},
                     name="motor")
    return m


def check_profile(kind: str, profile: Any, follower: Any, must_fail: str | None
                  ) -> tuple[str, ...]:
    """A cam or curved slot with a given profile. A profile that crosses itself, encloses no
    area, repeats a point or has r(alpha) <= 0 (must_fail says which) is rejected with a
    ModelError naming the joint, at the latest when the model is packed (counts)."""
    model = cam_base(kind)
    names, bounds = {"cam", "follower", "pivot", "guide", "motor", "contact"}, {"joint": 3}
    entry = f"joint 'contact' ({kind})"
    try:
        if kind == "cam":
            model.add_cam(["cam", "follower"], profile, follower, name="contact")
        else:
            model.add_point_on_curve(["cam", "follower"], profile, follower, name="contact")
        model.counts()
    except mbd2d.ModelError as exc:
        assert_names_entry(exc, names, bounds)
        assert exc.entry.startswith(entry), f"the error names {exc.entry!r}, not {entry!r}"
        return ("ModelError",)
    assert must_fail is None, f"a {must_fail} profile was accepted: {profile!r}"
    return ("ok",) + exercise(model, names, bounds)


SETTINGS_MODELS = ["slider_crank.toml", "door_two_hinges.toml", "cam_follower.toml",
                   "fourbar_seed.toml", "gears"]


def check_analysis_call(base: str, method: str, kw: dict[str, Any]) -> tuple[str, ...]:
    """Analysis calls with hostile settings and states on a valid model: ModelError naming
    "analysis", "state" or the model, an AnalysisError, or finite results."""
    model = from_dict(BASE[base])
    names = {model.name} | {c.name for c in model.constraints} | {b.name for b in model.bodies}
    bounds = {"body": len(model.bodies), "joint": len(model.joints),
              "driver": len(model.drivers)}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            value = getattr(model, method)(**kw)
        except mbd2d.ModelError as exc:
            assert_names_entry(exc, names, bounds)
            result = "ModelError"
        except mbd2d.AnalysisError as exc:
            _analysis_error(exc, method)
            result = type(exc).__name__
        except mbd2d.InsufficientMemoryError as exc:
            _memory_error(exc, method)
            result = "InsufficientMemoryError"
        else:
            if method == "kinematics":
                _finite("kinematics results", value.t, value.q,
                        *(x for x in (value.qd, value.qdd) if x is not None))
            elif method == "analyze_dof":
                _finite("the DOF report's configuration", value.q)
            else:
                _finite(f"model.{method}", value)
            result = "ok"
    bad = [f"{w.category.__name__}: {w.message}" for w in caught
           if not issubclass(w.category, ALLOWED_WARNINGS)]
    assert not bad, f"unexpected warnings: {bad}"
    return (result,)


# private level: f2py turns a wrong shape, type or an integer beyond C int into these before the
# Fortran is called. They are acceptable ONLY at the private _core level, never from the API.
F2PY_ERRORS = (ValueError, TypeError, OverflowError)


def _core_call(fn: str, args: tuple[Any, ...]) -> Any:
    """Call a _core function; numpy's casting warnings from the f2py argument conversion
    (complex to real, NaN to int) belong to the f2py layer, like its ValueError."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            out = getattr(_core, fn)(*args)
        except F2PY_ERRORS as exc:
            out = exc
    for w in caught:
        assert issubclass(w.category, RuntimeWarning) and (
            "cast" in str(w.message) or "imaginary" in str(w.message)), \
            f"unexpected warning from {fn}: {w.category.__name__}: {w.message}"
    return out


def _status_msg(fn: str, status: Any, msg: Any) -> str:
    assert isinstance(status, int), f"{fn}: status {status!r} is not an int"
    text = msg.decode("utf-8", "replace").strip() if isinstance(msg, bytes) else str(msg).strip()
    if status != 0:
        assert text, f"{fn} returned status {status} with an empty message"
    return text


def _c_int(x: Any) -> int:
    """The integer f2py made of a scalar argument (it accepts '3', 1.5, [3])."""
    return int(float(np.asarray(x).ravel()[0]))


def check_core(fn: str, args: tuple[Any, ...]) -> str:
    """A _core call: an f2py ValueError/TypeError/OverflowError, or a status with a message;
    status 0 means sensible sizes and finite outputs."""
    out = _core_call(fn, args)
    if isinstance(out, BaseException):
        return f"f2py:{type(out).__name__}"
    if fn == "core_sizes":
        nq, neq, status, msg, bad = out
        _status_msg(fn, status, msg)
        nc = np.size(args[1]) // 8          # f2py takes any (8, nc)-shaped table
        assert 0 <= bad <= nc, f"bad = {bad} for {nc} constraints"
        if status == 0:
            nb = _c_int(args[0])
            # nc = 0: free bodies (a contact model), no equations
            assert 3 * nb <= nq <= 3 * nb + nc and min(nc, 1) <= neq <= 3 * nc, \
                f"status 0 but sizes nq = {nq}, neq = {neq} for nb = {nb}, nc = {nc}"
    elif fn == "core_eval":
        phi, jac, nu, gam, status, msg, bad = out
        _status_msg(fn, status, msg)
        if status == 0:
            _finite("core_eval outputs (Phi, J, nu, gamma) with status 0", phi, jac, nu, gam)
    elif fn == "core_kinematics":
        qout, qdout, qddout, iinfo, rinfo, qsing, dep, red, tpass, status, msg = out
        _status_msg(fn, status, msg)
        n = int(iinfo[0])
        assert 0 <= n <= qout.shape[1], f"{n} rows reported for {qout.shape[1]}"
        if status == 0:
            assert n == qout.shape[1], f"status 0 but {n} of {qout.shape[1]} rows"
            _finite("core_kinematics outputs with status 0", qout, qdout, qddout, rinfo)
        else:
            _no_nan("core_kinematics rows computed before the failure", qout[:, :n],
                    qdout[:, :n], qddout[:, :n])
    elif fn == "core_analyze":
        q, rank, mobility, red, dep, resid, worst, status, msg = out
        _status_msg(fn, status, msg)
        if status == 0:
            _finite("core_analyze outputs with status 0", q, resid)
            assert 0 <= rank <= len(q), f"rank {rank} for {len(q)} coordinates"
    elif fn == "core_profile":
        pts, status, msg = out
        _status_msg(fn, status, msg)
        if status == 0:
            _finite("core_profile points with status 0", pts)
    else:  # pragma: no cover
        raise AssertionError(fn)
    return f"status:{out[-2] if fn != 'core_sizes' else out[2]}"


# ------------------------------------------------------------------------------------------
# strategies (drawn in the pytest process)
# ------------------------------------------------------------------------------------------
def _toml_str(s: str) -> str:
    out = []
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ch == "\x7f":
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


class NotToml(Exception):
    """The value has no TOML form (None, a non-string key, a tuple...)."""


def toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        if any(0xD800 <= ord(c) <= 0xDFFF for c in v):
            raise NotToml(v)
        return _toml_str(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        if not all(isinstance(k, str) for k in v):
            raise NotToml(v)
        return "{" + ", ".join(f"{toml_value(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise NotToml(v)


def to_toml(data: Any) -> str | None:
    """TOML text for model data (every top-level key as an inline value), or None."""
    if not isinstance(data, dict):
        return None
    if not all(isinstance(k, str) for k in data):
        return None
    try:
        return "".join(f"{toml_value(k)} = {toml_value(v)}\n" for k, v in data.items())
    except NotToml:
        return None


def _walk(node: Any, prefix: tuple = ()) -> list[tuple[tuple, Any]]:
    out = [(prefix, node)]
    if isinstance(node, dict):
        for k, v in node.items():
            out += _walk(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += _walk(v, prefix + (i,))
    return out


def _get(root: Any, path: tuple) -> Any:
    for p in path:
        root = root[p]
    return root


def _set(root: Any, path: tuple, value: Any) -> None:
    _get(root, path[:-1])[path[-1]] = value


def _deepcopy(x: Any) -> Any:
    return pickle.loads(pickle.dumps(x))


SAFE_TEXT = st.text(alphabet=st.characters(blacklist_categories=("Cs",)), max_size=10)
NAMEISH = st.one_of(st.sampled_from(["ground", "crank", "rod", "slider", "coupler", "cam",
                                     "follower", "motor", "guide", "O2", "A", "x", "theta",
                                     "", " ", "a b", "1abc", "é", "ground ", "Ground",
                                     "n" * 64, "revolute1", "driver1"]), SAFE_TEXT)
FLOATS = st.floats(allow_nan=True, allow_infinity=True)
SMALL_FLOATS = st.floats(-10, 10, allow_nan=False)

# values of a wrong type (or shape) wherever they land
WRONG_TYPE = st.one_of(
    NAMEISH,
    st.booleans(),
    st.none(),
    st.integers(-3, 3),
    st.sampled_from([[], [[]], [[[]]], {}, {"x": 1.0}, {"circle": {}}, [1.0], [1.0, 2.0, 3.0, 4.0],
                     [[1.0, 2.0], [3.0]], [["a", "b"], ["c", "d"]], [None, None], [True, False],
                     [[0.0, 0.0], [0.0, 0.0], [0.0, 0.0]], [1.0, "2"], [{}, {}],
                     ["ground", "ground"], ["crank"], ["crank", "rod", "slider"],
                     {"poly": []}, {"poly": "1"}, {"harmonic": [{}]},
                     {"harmonic": {"amplitude": 1.0}}, {"poly": [1.0], "extra": 1}]),
    st.recursive(st.one_of(st.none(), st.booleans(), SMALL_FLOATS, SAFE_TEXT),
                 lambda c: st.lists(c, max_size=3)
                 | st.dictionaries(st.sampled_from(ALL_KEYS) | SAFE_TEXT, c, max_size=3),
                 max_leaves=6),
)
# numbers that are not finite or do not fit a double
NONFINITE = st.sampled_from([math.nan, math.inf, -math.inf, -math.nan, 10**400, -(10**400),
                             2**1024, 10**309])
# finite numbers at the edges
EXTREME = st.one_of(
    st.sampled_from([0, 0.0, -0.0, -1, -1.0, 1e308, -1e308, 1.7976931348623157e308, 1e300,
                     -1e300, 1e154, 1e20, -1e20, 1e10, 1e8, 1e6, 5e-324, -5e-324, 1e-300,
                     2.2250738585072014e-308, 1e-12, 2**53 + 1, 2**63 - 1, -(2**63)]),
    st.floats(allow_nan=False, allow_infinity=False),
    st.integers(-(2**63), 2**63 - 1),
)


def _zero_vector() -> st.SearchStrategy:
    return st.sampled_from([[0.0, 0.0], [0, 0], [-0.0, 0.0], [0.0, -0.0]])


def crossing_profiles() -> st.SearchStrategy:
    """Closed curves that are not simple: figure-eight, bow-tie, star, double loop, spiral;
    and degenerate ones: collinear points, repeated points, Fourier radius < 0 somewhere."""

    @st.composite
    def build(draw: Any) -> tuple[dict[str, Any], str]:
        kind = draw(st.sampled_from(["figure-eight", "bow-tie", "star", "double-loop",
                                     "spiral", "collinear", "repeated", "fourier-negative"]))
        scale = draw(st.floats(0.2, 5.0))
        angle = draw(st.floats(0.0, 2 * math.pi))
        shift = np.array([draw(st.floats(-1, 1)), draw(st.floats(-1, 1))])
        if kind == "fourier-negative":
            k = draw(st.integers(1, 4))
            a0 = draw(st.floats(0.2, 2.0))
            ak = a0 * draw(st.floats(1.05, 3.0))        # |a_k| > a0: r < 0 somewhere
            a = [a0] + [0.0] * (k - 1) + [ak * draw(st.sampled_from([1, -1]))]
            spec = {"fourier": {"center": shift.tolist(), "a": a}}
            return spec, kind
        if kind == "figure-eight":
            n = draw(st.integers(8, 40))
            t = np.linspace(0, 2 * np.pi, n, endpoint=False) + draw(st.floats(0, 0.3))
            pts = np.column_stack([np.sin(t), np.sin(t) * np.cos(t)])
        elif kind == "bow-tie":
            pts = np.array([[-1, -1], [1, 1], [1, -1], [-1, 1]], dtype=float)
            pts[:, 1] *= draw(st.floats(0.3, 2.0))
        elif kind == "star":
            p, q = draw(st.sampled_from([(5, 2), (7, 2), (7, 3), (8, 3), (9, 4)]))
            t = 2 * np.pi * q * np.arange(p) / p
            pts = np.column_stack([np.cos(t), np.sin(t)])
        elif kind == "double-loop":
            n = draw(st.integers(5, 12))
            t = np.linspace(0, 4 * np.pi, 2 * n, endpoint=False)
            r = 1.0 + draw(st.sampled_from([0.0, 0.05, 0.2])) * t
            pts = np.column_stack([r * np.cos(t), r * np.sin(t)])
        elif kind == "spiral":
            n = draw(st.integers(10, 30))
            t = np.linspace(0, 4 * np.pi, n, endpoint=False)
            pts = np.column_stack([(1 + 0.1 * t) * np.cos(t), (1 + 0.1 * t) * np.sin(t)])
        elif kind == "collinear":    # distinct points on a line, in any order
            s = np.array(draw(st.permutations(list(range(-5, 6)))))[:draw(st.integers(4, 11))]
            pts = np.column_stack([s, 0.5 * s]) * 0.3
        else:  # repeated
            n = draw(st.integers(4, 10))
            t = np.linspace(0, 2 * np.pi, n, endpoint=False)
            pts = np.column_stack([np.cos(t), np.sin(t)])
            i = draw(st.integers(0, n - 1))
            pts[(i + 1) % n] = pts[i]
        c, s = math.cos(angle), math.sin(angle)
        pts = scale * pts @ np.array([[c, s], [-s, c]]) + shift
        return {"spline": {"points": pts.tolist()}}, kind

    return build()


GOOD_PROFILES = st.sampled_from([
    {"circle": {"center": [0.4, 0.0], "radius": 1.0}},
    {"fourier": {"center": [0.0, 0.0], "a": [1.0, 0.1, 0.05], "b": [0.1, 0.0]}},
    {"spline": {"points": [[1.0, 0.0], [0.7, 0.7], [0.0, 0.9], [-0.7, 0.7], [-1.0, 0.0],
                           [-0.7, -0.7], [0.0, -1.1], [0.7, -0.7]]}},
])
FOLLOWERS = st.one_of(
    st.sampled_from([{"point": [0.0, 0.0]}, {"roller": {"center": [0.0, 0.0], "radius": 0.25}},
                     {"flat": {"point": [0.0, 0.0], "normal": [0.0, -1.0]}}]),
    st.builds(lambda c, r: {"roller": {"center": c, "radius": r}},
              st.lists(SMALL_FLOATS, min_size=2, max_size=2), st.floats(-1, 3)),
    st.builds(lambda p, n: {"flat": {"point": p, "normal": n}},
              st.lists(SMALL_FLOATS, min_size=2, max_size=2),
              st.lists(SMALL_FLOATS, min_size=2, max_size=2) | _zero_vector()),
)
RANDOM_PROFILES = st.one_of(
    st.builds(lambda pts: {"spline": {"points": pts}},
              st.lists(st.lists(st.floats(-3, 3), min_size=2, max_size=2), min_size=0,
                       max_size=12)),
    st.builds(lambda c, a, b: {"fourier": {"center": c, "a": a, "b": b}},
              st.lists(SMALL_FLOATS, min_size=2, max_size=2),
              st.lists(st.floats(-2, 2), min_size=0, max_size=5),
              st.lists(st.floats(-2, 2), min_size=0, max_size=5)),
    st.builds(lambda c, r: {"circle": {"center": c, "radius": r}},
              st.lists(SMALL_FLOATS, min_size=2, max_size=2), st.floats(-1, 3)),
)


# ------------------------------------------------------------------------------------------
# 1. TOML / dict level
# ------------------------------------------------------------------------------------------
def _entries_with(data: dict[str, Any], key: str) -> list[tuple]:
    return [(sec, i) for sec in SECTIONS if isinstance(data.get(sec), list)
            for i, e in enumerate(data[sec]) if isinstance(e, dict) and key in e]


def _all_names(data: dict[str, Any]) -> list[str]:
    return sorted(_data_names(data)[0]) or ["ground"]


def mutate_structure(draw: Any, data: dict[str, Any]) -> str:
    """One structural mutation of model data; returns what it did."""
    op = draw(st.sampled_from(["delete-key", "unknown-key", "wrong-type", "list-length",
                               "empty-section", "self-joint", "zero-axis", "duplicate-name",
                               "unknown-reference", "unknown-type", "entry-not-table",
                               "section-not-array", "bad-profile", "swap-entry"]))
    paths = _walk(data)[1:]
    if op == "delete-key":
        keyed = [p for p, _ in paths if isinstance(_get(data, p[:-1]), dict)]
        if keyed:
            p = draw(st.sampled_from(keyed))
            del _get(data, p[:-1])[p[-1]]
            return f"delete {p}"
    if op == "unknown-key":
        tables = [p for p, v in _walk(data) if isinstance(v, dict)]
        p = draw(st.sampled_from(tables))
        key = draw(st.sampled_from(["colour", "Name", "TYPE", "bodies ", "point", "points",
                                    "axis", "axes", "q0", "v0", "force", "mass", "curve",
                                    "profile", "f", "joint"]) | SAFE_TEXT)
        _get(data, p)[key] = _deepcopy(draw(WRONG_TYPE | SMALL_FLOATS))
        return f"unknown key {key!r} at {p}"
    if op == "wrong-type" and paths:
        p = draw(st.sampled_from([p for p, _ in paths]))
        _set(data, p, _deepcopy(draw(WRONG_TYPE)))
        return f"wrong type at {p}"
    if op == "list-length":
        lists = [p for p, v in paths if isinstance(v, list)]
        if lists:
            p = draw(st.sampled_from(lists))
            v = _get(data, p)
            if v and draw(st.booleans()):
                del v[draw(st.integers(0, len(v) - 1)):]
            else:
                v.append(_deepcopy(v[0] if v and draw(st.booleans()) else draw(WRONG_TYPE)))
            return f"list length at {p}"
    if op == "empty-section":
        sec = draw(st.sampled_from(SECTIONS + ("model",)))
        how = draw(st.sampled_from(["empty", "delete", "empty-table"]))
        if how == "delete":
            data.pop(sec, None)
        else:
            data[sec] = [] if how == "empty" and sec != "model" else {}
        return f"{how} {sec}"
    if op == "self-joint":
        cand = _entries_with(data, "bodies")
        if cand:
            sec, i = draw(st.sampled_from(cand))
            b = draw(st.sampled_from(_all_names(data) + ["ground"]))
            data[sec][i]["bodies"] = [b, b]
            return f"self-joint {sec} #{i + 1} on {b}"
    if op == "zero-axis":
        cand = [p for p, _ in paths if p[-1] in ("axes", "axis", "normal")]
        if cand:
            p = draw(st.sampled_from(cand))
            if p[-1] == "axes":
                _set(data, p, _deepcopy([draw(_zero_vector()), [1.0, 0.0]] if draw(st.booleans())
                                        else [[1.0, 0.0], draw(_zero_vector())]))
            else:
                _set(data, p, _deepcopy(draw(_zero_vector())))
            return f"zero axis at {p}"
    if op == "duplicate-name":
        cand = _entries_with(data, "name")
        if cand:
            sec, i = draw(st.sampled_from(cand))
            data[sec][i]["name"] = draw(st.sampled_from(_all_names(data) + ["ground"]))
            return f"duplicate name at {sec} #{i + 1}"
    if op == "unknown-reference":
        cand = [p for p, _ in paths if p[-1] in ("bodies", "body", "carrier", "joint")
                or (len(p) > 1 and p[-2] == "bodies")]
        if cand:
            p = draw(st.sampled_from(cand))
            v = draw(st.sampled_from(["nobody", "Ground", "crank2", "", "motor", "O2"]))
            _set(data, p, [v, v + "x"] if p[-1] == "bodies" else v)
            return f"unknown reference at {p}"
    if op == "unknown-type":
        cand = _entries_with(data, "type")
        if cand:
            sec, i = draw(st.sampled_from(cand))
            data[sec][i]["type"] = draw(st.sampled_from(
                JOINT_TYPES + DRIVER_TYPES + ["Revolute", "hinge", "", "spring", "force"])
                | SAFE_TEXT)
            return f"type of {sec} #{i + 1}"
    if op == "entry-not-table":
        cand = [(s, i) for s in SECTIONS if isinstance(data.get(s), list)
                for i in range(len(data[s]))]
        if cand:
            sec, i = draw(st.sampled_from(cand))
            data[sec][i] = _deepcopy(draw(st.sampled_from([5, "revolute", [], [{}], True, 1.5])))
            return f"{sec} #{i + 1} not a table"
    if op == "section-not-array":
        sec = draw(st.sampled_from(SECTIONS + ("model",)))
        data[sec] = _deepcopy(draw(st.sampled_from([5, "x", {"name": "a"}, [1, 2], True, [[]]])))
        return f"section {sec} of a wrong form"
    if op == "bad-profile":
        cand = [p for p, _ in paths if p[-1] in ("profile", "curve")]
        if cand:
            p = draw(st.sampled_from(cand))
            spec = draw(crossing_profiles().map(lambda x: x[0]) | RANDOM_PROFILES)
            _set(data, p, _deepcopy(spec))
            return f"profile at {p}"
    if op == "swap-entry":
        a, b = draw(st.sampled_from(SECTIONS)), draw(st.sampled_from(SECTIONS))
        if isinstance(data.get(a), list) and data[a] and isinstance(data.get(b), list):
            data[b].insert(draw(st.integers(0, len(data[b]))),
                           _deepcopy(draw(st.sampled_from(data[a]))))
            return f"a {a} entry in [[{b}]]"
    # fallback: replace a random value
    if paths:
        p = draw(st.sampled_from([p for p, _ in paths]))
        _set(data, p, _deepcopy(draw(WRONG_TYPE)))
        return f"wrong type at {p}"
    data["body"] = []
    return "empty"


def _numeric_paths(data: Any) -> list[tuple]:
    return [p for p, v in _walk(data)[1:]
            if isinstance(v, (int, float)) and not isinstance(v, bool)]


@hostile_settings(300)
@given(st.data())
def test_toml_structure_mutations(data: st.DataObject) -> None:
    """Valid models with missing and unknown keys, values of a wrong type, wrong lengths,
    empty sections, self-joints, zero axes, duplicate names, unknown bodies and types,
    crossing profiles: a ModelError naming the entry, or a model that behaves. from_dict and
    load (from a file) agree."""
    _count("test_toml_structure_mutations")
    base = data.draw(st.sampled_from(BASE_NAMES), label="base")
    model = _deepcopy(BASE[base])
    ops = [mutate_structure(data.draw, model) for _ in range(data.draw(st.integers(1, 3)))]
    note(f"mutations: {ops}")
    WORKER.call("check_model_data", model, to_toml(model))


@hostile_settings(200, shrink=True)
@given(st.data())
def test_toml_nonfinite_numbers(data: st.DataObject) -> None:
    """NaN, infinities and integers beyond the double range anywhere a number goes (TOML
    reads integers of any size): a ModelError naming the entry."""
    _count("test_toml_nonfinite_numbers")
    base = data.draw(st.sampled_from(BASE_NAMES), label="base")
    model = _deepcopy(BASE[base])
    paths = _numeric_paths(model)
    for p in data.draw(st.lists(st.sampled_from(paths), min_size=1, max_size=2), label="at"):
        _set(model, p, data.draw(NONFINITE, label=f"value at {p}"))
    out = WORKER.call("check_model_data", model, to_toml(model))
    assert out[0] == "build:ModelError", f"a non-finite number was accepted: {out}"


@hostile_settings(250)
@given(st.data())
def test_toml_extreme_numbers(data: st.DataObject) -> None:
    """Finite numbers at the edges (huge, tiny, subnormal, zero, negative, large integers)
    anywhere a number goes: a ModelError naming the entry, or a model whose counts, short
    run, DOF report and Phi at q0 end in typed errors or finite outputs; no hang."""
    _count("test_toml_extreme_numbers")
    base = data.draw(st.sampled_from(BASE_NAMES), label="base")
    model = _deepcopy(BASE[base])
    paths = _numeric_paths(model)
    for p in data.draw(st.lists(st.sampled_from(paths), min_size=1, max_size=3), label="at"):
        _set(model, p, data.draw(EXTREME, label=f"value at {p}"))
    WORKER.call("check_model_data", model, to_toml(model))


@hostile_settings(150, shrink=True)
@given(st.data())
def test_from_dict_non_toml_shapes(data: st.DataObject) -> None:
    """from_dict with what parsed TOML never holds but a dict can: non-string keys (also as
    joint keywords), tuples, sets, bytes, None, a non-mapping model: ModelError, never a raw
    TypeError."""
    _count("test_from_dict_non_toml_shapes")
    odd = st.sampled_from([1, 2.5, None, True, (1, 2), b"name", frozenset({"a"})])
    base = data.draw(st.sampled_from(BASE_NAMES), label="base")
    model: Any = _deepcopy(BASE[base])
    op = data.draw(st.sampled_from(["key", "key", "value", "top"]), label="op")
    if op == "top":
        model = data.draw(st.sampled_from([None, [], "model", 5, [model], (1, 2), b"x"]))
    else:
        tables = [p for p, v in _walk(model) if isinstance(v, dict)]
        p = data.draw(st.sampled_from(tables), label="table")
        if op == "key":
            _get(model, p)[data.draw(odd, label="key")] = data.draw(SMALL_FLOATS | odd)
        else:
            keys = list(_get(model, p))
            if keys:
                _get(model, p)[data.draw(st.sampled_from(keys))] = data.draw(
                    odd | st.sampled_from([(1.0, 2.0), ((0.0, 0.0), (1.0, 0.0)), {1, 2},
                                           b"\xff", ("ground", "crank")]), label="value")
    WORKER.call("check_model_data", model, None)


def _named_cases() -> list[tuple[str, Any, Any]]:
    """(what, model data, the entry the ModelError must name) for each kind of malformed
    model the issue lists."""
    def edit(base: str, fn: Callable[[dict[str, Any]], Any]) -> dict[str, Any]:
        d = _deepcopy(BASE[base])
        fn(d)
        return d

    fig8 = [[math.sin(t), math.sin(t) * math.cos(t)]
            for t in np.linspace(0, 2 * np.pi, 16, endpoint=False)]
    bowtie = [[-1.0, -1.0], [1.0, 1.0], [1.0, -1.0], [-1.0, 1.0]]
    sc, fb, cam = "slider_crank.toml", "fourbar_grashof.toml", "cam_follower.toml"
    return [
        ("empty model", {}, "model"),
        ("empty sections", {"model": {}, "body": [], "joint": [], "driver": []}, "model"),
        ("bodies only", edit(fb, lambda d: (d.pop("joint"), d.pop("driver"))), "model"),
        ("joints of no body", edit(fb, lambda d: d.pop("body")), "joint 'O2' (revolute)"),
        ("missing q0", edit(fb, lambda d: d["body"][1].pop("q0")), "[[body]] #2 'coupler'"),
        ("missing name", edit(fb, lambda d: d["body"][0].pop("name")), "[[body]] #1"),
        ("missing type", edit(fb, lambda d: d["joint"][2].pop("type")), "[[joint]] #3 'B'"),
        ("missing points", edit(fb, lambda d: d["joint"][0].pop("points")),
         "joint 'O2' (revolute)"),
        ("missing f", edit(fb, lambda d: d["driver"][0].pop("f")), "[[driver]] #1 'motor'"),
        ("unknown key", edit(fb, lambda d: d["joint"][1].update(colour="red")),
         "joint 'A' (revolute)"),
        ("unknown body key", edit(fb, lambda d: d["body"][0].update(velocity=1.0)),
         "[[body]] #1 'crank'"),
        ("unknown section", edit(fb, lambda d: d.update(spring=[{"k": 1.0}])), "<dict>"),
        ("unknown model key", edit(fb, lambda d: d["model"].update(units="mm")), "[model]"),
        ("unknown joint type", edit(fb, lambda d: d["joint"][0].update(type="hinge")),
         "joint 'O2' (hinge)"),
        ("unknown driver type", edit(fb, lambda d: d["driver"][0].update(type="motor")),
         "driver 'motor'"),
        ("unknown body", edit(fb, lambda d: d["joint"][3].update(bodies=["rocker", "frame"])),
         "joint 'O4' (revolute)"),
        ("self-joint", edit(fb, lambda d: d["joint"][1].update(bodies=["crank", "crank"])),
         "joint 'A' (revolute)"),
        ("ground to ground", edit(fb, lambda d: d["joint"][0].update(bodies=["ground"] * 2)),
         "joint 'O2' (revolute)"),
        ("self relative-angle driver", edit(fb, lambda d: (
            d["driver"][0].pop("body"), d["driver"][0].pop("coordinate"),
            d["driver"][0].update(type="relative-angle", bodies=["crank", "crank"]))),
         "driver 'motor'"),
        ("driver with body and bodies", edit(fb, lambda d: d["driver"][0].update(
            bodies=["ground", "crank"])), "driver 'motor'"),
        ("duplicate body", edit(fb, lambda d: d["body"][2].update(name="crank")),
         "body 'crank'"),
        ("joint named like a body", edit(fb, lambda d: d["joint"][0].update(name="crank")),
         "joint 'crank' (revolute)"),
        ("body named ground", edit(fb, lambda d: d["body"][0].update(name="ground")),
         "body 'ground'"),
        ("zero axis", edit(sc, lambda d: d["joint"][3].update(axes=[[0.0, 0.0], [1.0, 0.0]])),
         "joint 'guide' (translational)"),
        ("zero second axis", edit(sc, lambda d: d["joint"][3].update(axes=[[1, 0], [0, 0]])),
         "joint 'guide' (translational)"),
        ("zero slot axis", edit("yoke", lambda d: d["joint"][2].update(axis=[0.0, -0.0])),
         "joint 'slot' (revolute-translational)"),
        ("zero flat normal", edit("fourier_cam", lambda d: d["joint"][2].update(
            follower={"flat": {"point": [0, 0], "normal": [0, 0]}})),
         "joint 'contact' (cam)"),
        ("zero rolling axis", edit("rolling", lambda d: d["joint"][3].update(axis=[0, 0])),
         "joint 'roll' (rolling-disc)"),
        ("figure-eight profile", edit(cam, lambda d: d["joint"][2].update(
            profile={"spline": {"points": fig8}})), "joint 'contact' (cam)"),
        ("bow-tie profile", edit(cam, lambda d: d["joint"][2].update(
            profile={"spline": {"points": bowtie}})), "joint 'contact' (cam)"),
        ("Fourier r < 0", edit(cam, lambda d: d["joint"][2].update(
            profile={"fourier": {"a": [1.0, 1.5]}})), "joint 'contact' (cam)"),
        ("crossing slot curve", edit("weld_slot", lambda d: d["joint"][2].update(
            curve={"spline": {"points": bowtie}})), "joint 'slot' (point-on-curve)"),
        ("roller larger than a concave radius", edit(cam, lambda d: d["joint"][2].update(
            profile={"spline": {"points": [[1, 0], [0.2, 0.2], [0, 1], [-1, 0], [0, -1]]}},
            follower={"roller": {"center": [0, 0], "radius": 0.8}})),
         "joint 'contact' (cam)"),
        ("zero radius", edit(cam, lambda d: d["joint"][2]["profile"]["circle"].update(
            radius=0.0)), "joint 'contact' (cam)"),
        ("negative distance", edit("slide", lambda d: d["joint"][2].update(distance=-1.0)),
         "joint 'tie' (distance)"),
        ("q0 of two numbers", edit(fb, lambda d: d["body"][0].update(q0=[0.5, 0.0])),
         "body 'crank'"),
        ("points as a string", edit(fb, lambda d: d["joint"][0].update(points="0, 0")),
         "joint 'O2' (revolute)"),
        ("bodies as a string", edit(fb, lambda d: d["joint"][0].update(bodies="ground crank")),
         "joint 'O2' (revolute)"),
        ("NaN point", edit(fb, lambda d: d["joint"][2]["points"][0].__setitem__(0, math.nan)),
         "joint 'B' (revolute)"),
        ("infinite q0", edit(fb, lambda d: d["body"][1]["q0"].__setitem__(2, -math.inf)),
         "body 'coupler'"),
        ("NaN gravity", edit(fb, lambda d: d["model"].update(gravity=[0.0, math.nan])),
         "[model]"),
        ("driver of a missing joint", edit("slide", lambda d: d["driver"][0].update(
            joint="rail")), "driver 'stroke'"),
        ("gear carrier among the gears", edit("gears", lambda d: d["joint"][3].update(
            carrier="planet")), "joint 'mesh' (gear)"),
        ("[[body]] as a table", edit(fb, lambda d: d.update(body={"name": "x"})), "<dict>"),
        ("body entry not a table", edit(fb, lambda d: d["body"].__setitem__(0, "crank")),
         "[[body]] #1"),
        ("[[force]] without a type", edit(fb, lambda d: d.update(force=[{"body": "crank"}])),
         "[[force]] #1"),
        ("collinear spline under a roller", edit(cam, lambda d: d["joint"][2].update(
            profile={"spline": {"points": [[0, 0], [2, 0], [1, 0], [3, 0]]}})),
         "joint 'contact' (cam)"),
        ("integer beyond the double range", edit(fb, lambda d: d["body"][0].update(
            q0=[10**400, 0, 0])), "body 'crank'"),
        ("huge integer coefficient", edit(fb, lambda d: d["driver"][0].update(
            f={"poly": [0, -(10**309)]})), "driver 'motor'"),
        ("non-string key in a joint (from_dict only)", edit(fb, lambda d: d["joint"][0].update(
            {1: 2.0})), ("[[joint]] #1", "joint 'O2' (revolute)")),
        ("unsortable unknown keys (from_dict only)", edit(fb, lambda d: d["body"][0].update(
            {None: 1.0, "colour": "red"})), ("[[body]] #1", "body 'crank'")),
    ]


NAMED_CASES = _named_cases()


def check_named(data: dict[str, Any], expected: str | tuple[str, ...]) -> str:
    """A named malformed model: a ModelError, at build or at latest when the model is packed,
    whose entry is the expected one."""
    names, bounds = _data_names(data)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            from_dict(data).counts()
    except mbd2d.ModelError as exc:
        assert_names_entry(exc, names, bounds)
        assert exc.entry.startswith(expected), \
            f"the error names {exc.entry!r}, expected {expected!r}: {exc}"
        return str(exc)
    raise AssertionError("the malformed model was accepted")


@pytest.mark.parametrize("case", NAMED_CASES, ids=[c[0] for c in NAMED_CASES])
def test_named_malformed_models(case: tuple[str, Any, str]) -> None:
    """The issue's list, one fixed case each (empty models, missing and unknown keys, wrong
    types, self-joints, zero-length axes, crossing profiles, ...): a ModelError that names
    the right entry. (Not drawn by hypothesis: every case runs, in order.)"""
    _count("test_named_malformed_models")
    what, data, expected = case
    WORKER.call("check_named", data, expected)


def _damage_text(draw: Any, text: str) -> str | bytes:
    op = draw(st.sampled_from(["truncate", "delete-line", "duplicate-line", "insert",
                               "replace-char", "bytes", "swap-lines", "garbage"]))
    lines = text.splitlines(keepends=True)
    if op == "truncate":
        return text[:draw(st.integers(0, len(text)))]
    if op == "delete-line":
        i = draw(st.integers(0, len(lines) - 1))
        return "".join(lines[:i] + lines[i + 1:])
    if op == "duplicate-line":
        i = draw(st.integers(0, len(lines) - 1))
        return "".join(lines[:i + 1] + lines[i:])
    if op == "swap-lines":
        i, j = draw(st.integers(0, len(lines) - 1)), draw(st.integers(0, len(lines) - 1))
        lines[i], lines[j] = lines[j], lines[i]
        return "".join(lines)
    if op == "insert":
        i = draw(st.integers(0, len(text)))
        ins = draw(st.sampled_from(["[", "]", "=", '"', "\n", "[[joint]]\n", "[[body]]\n",
                                    "name = 1\n", "x = nan\n", "\x00", "#", "{", ",",
                                    "[model]\n", "[[force]]\nx = 1\n", "\ufeff",
                                    "q0 = [1e999, 0, 0]\n"]) | SAFE_TEXT)
        return text[:i] + ins + text[i:]
    if op == "replace-char":
        i = draw(st.integers(0, max(len(text) - 1, 0)))
        return text[:i] + draw(st.characters(blacklist_categories=("Cs",))) + text[i + 1:]
    if op == "bytes":
        raw = text.encode()
        i = draw(st.integers(0, len(raw)))
        return raw[:i] + draw(st.sampled_from([b"\xff", b"\xc3", b"\x80\x80", b"\xfe\xff",
                                               b"\xed\xa0\x80"])) + raw[i:]
    return draw(SAFE_TEXT | st.sampled_from(["", "[[body]]", "[[body]]\nname = 3",
                                             "body = 1", "[model]\nname = []"]))


@hostile_settings(150)
@given(st.data())
def test_toml_text_damage(data: st.DataObject) -> None:
    """Damaged TOML text (truncated, lines lost or repeated, stray brackets, non-UTF-8 bytes):
    mbd2d.loads and mbd2d.load end in a ModelError naming the source or the entry, or give
    a model that behaves."""
    _count("test_toml_text_damage")
    base = data.draw(st.sampled_from(BASE_NAMES), label="base")
    text = _damage_text(data.draw, BASE_TEXT[base])
    WORKER.call("check_model_text", text)


# ------------------------------------------------------------------------------------------
# 2. builder API
# ------------------------------------------------------------------------------------------
HOSTILE_ARG = st.one_of(
    WRONG_TYPE,
    NONFINITE,
    EXTREME,
    st.sampled_from([np.array([np.nan, 0.0]), np.array([0.0, np.inf]), np.zeros((2, 3)),
                     np.zeros((3, 2)), np.zeros(3), np.zeros((2, 2, 2)), np.array(1.0),
                     np.array(["a", "b"]), np.array([1j, 2.0]), np.array([None, 1.0]),
                     np.float64("nan"), np.int64(7), np.bool_(True), np.zeros(0),
                     np.array([[0.0, 0.0], [0.0, 0.0]]), np.array([1e308, 1e308]),
                     Fraction(1, 3), Fraction(10**400, 3), Decimal("1.5"), Decimal("nan"),
                     1 + 2j, b"ab", {1.0, 2.0}, frozenset(), range(2), (1.0, 2.0),
                     ((0.0, 0.0), (1.0, 0.0)), object()]),
)


def _maybe(valid: st.SearchStrategy) -> st.SearchStrategy:
    """Mostly plausible values, often hostile ones."""
    return st.one_of(valid, valid, HOSTILE_ARG)


VEC2 = st.lists(SMALL_FLOATS, min_size=2, max_size=2)
BODY_REF = st.sampled_from(["ground", "crank", "rod", "slider", "nobody", "Crank"])
PARAMS: dict[str, st.SearchStrategy] = {
    "bodies": _maybe(st.lists(BODY_REF, min_size=2, max_size=2)),
    "points": _maybe(st.lists(VEC2, min_size=2, max_size=2)),
    "axes": _maybe(st.lists(VEC2 | _zero_vector(), min_size=2, max_size=2)),
    "axis": _maybe(VEC2 | _zero_vector()),
    "distance": _maybe(st.floats(-2, 5)),
    "offset": _maybe(SMALL_FLOATS),
    "angle": _maybe(SMALL_FLOATS),
    "radii": _maybe(st.lists(st.floats(-1, 3), min_size=2, max_size=2)),
    "internal": _maybe(st.booleans()),
    "carrier": _maybe(BODY_REF),
    "phase": _maybe(st.none() | SMALL_FLOATS),
    "pressure_angle": _maybe(SMALL_FLOATS),
    "centers": _maybe(st.lists(VEC2, min_size=2, max_size=2)),
    "center": _maybe(VEC2),
    "point": _maybe(VEC2),
    "radius": _maybe(st.floats(-1, 3)),
    "profile": _maybe(GOOD_PROFILES | RANDOM_PROFILES | crossing_profiles().map(lambda x: x[0])),
    "curve": _maybe(GOOD_PROFILES | RANDOM_PROFILES | crossing_profiles().map(lambda x: x[0])),
    "follower": _maybe(FOLLOWERS),
    "body": _maybe(BODY_REF),
    "coordinate": _maybe(st.sampled_from(["x", "y", "theta", "X", "z", ""])),
    "value": _maybe(st.none() | SMALL_FLOATS),
    "f": _maybe(st.one_of(SMALL_FLOATS,
                          st.builds(lambda p: {"poly": p}, st.lists(SMALL_FLOATS, max_size=4)),
                          st.builds(lambda a, w: {"harmonic": [{"amplitude": a, "omega": w}]},
                                    SMALL_FLOATS, SMALL_FLOATS))),
    "joint": _maybe(st.sampled_from(["j1", "j2", "j3", "nojoint", "crank"])),
    "q0": _maybe(st.lists(SMALL_FLOATS, min_size=3, max_size=3)),
    "mass": _maybe(st.none() | st.floats(-1, 5)),
    "inertia": _maybe(st.none() | st.floats(-1, 5)),
}
METHOD_PARAMS = {   # method: (required, optional) arguments besides name
    "add_revolute": (["bodies", "points"], []),
    "add_translational": (["bodies", "points", "axes"], []),
    "add_cam": (["bodies", "profile", "follower"], []),
    "add_point_on_curve": (["bodies", "curve", "point"], []),
    "add_distance": (["bodies", "points", "distance"], []),
    "add_point_on_line": (["bodies", "points", "axis"], ["offset"]),
    "add_pin_in_slot": (["bodies", "points", "axis"], ["offset"]),
    "add_weld": (["bodies", "points"], ["angle"]),
    "add_gear": (["bodies", "radii"], ["internal", "carrier", "phase", "pressure_angle",
                                       "centers"]),
    "add_rack_pinion": (["bodies", "center", "point", "axis", "radius"], ["phase"]),
    "add_rolling_disc": (["bodies", "center", "point", "axis", "radius"], ["phase"]),
    "add_absolute": (["body", "coordinate"], ["value"]),
    "add_body": (["q0"], ["mass", "inertia"]),
}
NAME_ARG = st.one_of(st.none(), st.sampled_from(["j1", "j2", "j3", "d1"]), NAMEISH,
                     HOSTILE_ARG)


@st.composite
def builder_call(draw: Any) -> tuple[str, dict[str, Any]]:
    method = draw(st.sampled_from(sorted(METHOD_PARAMS) + ["add_driver", "add_joint"] * 2))
    kw: dict[str, Any] = {}
    if method == "add_driver":
        kw["type"] = draw(_maybe(st.sampled_from(DRIVER_TYPES)))
        kw["f"] = draw(PARAMS["f"])
        for key in draw(st.lists(st.sampled_from(["body", "coordinate", "bodies", "joint"]),
                                 unique=True, max_size=3)):
            kw[key] = draw(PARAMS[key])
    elif method == "add_joint":
        jtype = draw(_maybe(st.sampled_from(JOINT_TYPES)))
        kw["type"] = jtype
        allowed = sorted(joint_keys().get(jtype, ({"bodies"}, set()))[0]
                         if isinstance(jtype, str) else {"bodies"})
        keys = draw(st.lists(st.sampled_from(allowed + ["colour", "axes", "q0", "mass"]),
                             unique=True, min_size=0, max_size=len(allowed) + 1))
        for key in keys:
            kw[key] = draw(PARAMS.get(key, HOSTILE_ARG))
    else:
        required, optional = METHOD_PARAMS[method]
        for key in required + draw(st.lists(st.sampled_from(optional), unique=True)
                                   if optional else st.just([])):
            kw[key] = draw(PARAMS[key])
    if method == "add_body":
        kw["name"] = draw(NAME_ARG.filter(lambda x: x is not None))
    elif draw(st.booleans()):
        kw["name"] = draw(NAME_ARG)
    return method, kw


@hostile_settings(300)
@given(gravity=_maybe(st.just([0.0, -9.81])),
       calls=st.lists(builder_call(), min_size=1, max_size=6))
def test_builder_hostile_calls(gravity: Any, calls: list[tuple[str, dict[str, Any]]]) -> None:
    """Builder calls with hostile arguments (wrong types and shapes, NumPy arrays, NaN,
    infinities, zero axes, self-joints, zero or negative radii and distances, duplicate names,
    crossing profiles): each raises a ModelError naming the entry and changes nothing, or adds
    its entry; the resulting model behaves. (Leaving out a required argument of an add_*
    method is a Python TypeError by design, a programming error rather than model data, so
    it is not generated; add_joint and add_driver get every combination of keys.)"""
    _count("test_builder_hostile_calls")
    WORKER.call("check_builder", gravity, calls)


@hostile_settings(150)
@given(kind=st.sampled_from(["cam", "point-on-curve"]), bad=crossing_profiles(),
       follower=st.sampled_from([{"point": [0.0, 0.0]},
                                 {"roller": {"center": [0.0, 0.0], "radius": 0.1}},
                                 {"flat": {"point": [0.0, 0.0], "normal": [0.0, -1.0]}}]))
def test_crossing_profiles_are_rejected(kind: str, bad: tuple[dict[str, Any], str],
                                        follower: dict[str, Any]) -> None:
    """Figure-eights, bow-ties, stars, double loops, spirals, collinear or repeated points and
    Fourier profiles with r < 0 somewhere: always a ModelError naming the joint."""
    _count("test_crossing_profiles_are_rejected")
    spec, what = bad
    fol: Any = follower if kind == "cam" else [0.0, 0.0]
    WORKER.call("check_profile", kind, spec, fol, what)


@hostile_settings(150)
@given(kind=st.sampled_from(["cam", "point-on-curve"]),
       profile=RANDOM_PROFILES | GOOD_PROFILES, follower=FOLLOWERS)
def test_random_profiles(kind: str, profile: dict[str, Any], follower: Any) -> None:
    """Random splines (any number of points, anywhere), Fourier and circle profiles and
    followers: a ModelError naming the joint, or a model that behaves."""
    _count("test_random_profiles")
    fol = follower if kind == "cam" else [0.0, 0.0]
    WORKER.call("check_profile", kind, profile, fol, None)


TIME_ARG = st.one_of(st.sampled_from([0.0, 0.1, 1.0, -1.0, 1e-300, 5e-324, 1e8, 1e300, -1e308,
                                      1e308, 10**400, True, "1", None, [0.1], np.float64(0.1),
                                      np.nan, np.inf, -np.inf, Decimal("0.1"),
                                      Fraction(1, 10), np.array([0.1])]),
                     st.floats(-10, 10))
STEPS_ARG = st.sampled_from([-1, 0, 1, 2, 3, True, 2.0, "2", None, np.int64(2), np.int32(3),
                             10**9, 10**9 + 1, 2**31, 2**63, -(2**63), 1.5, np.nan, [2]])
TOL_ARG = st.sampled_from([None, 0, 0.0, -1.0, np.nan, np.inf, 1e-300, 1e-16, 1e-15, 1e-9,
                           0.5, 0.999, 1.0, 2.0, "1e-9", True, [1e-9], 10**400])
MAXIT_ARG = st.sampled_from([None, 0, -1, 1, 2, 50, 10**6, 10**6 + 1, 2**31, 2**63, 1.5,
                             True, "25", np.int64(5)])


@st.composite
def analysis_call(draw: Any) -> tuple[str, str, dict[str, Any]]:
    base = draw(st.sampled_from(SETTINGS_MODELS))
    method = draw(st.sampled_from(["kinematics", "kinematics", "analyze_dof", "phi",
                                   "jacobian", "nu", "gamma"]))
    kw: dict[str, Any] = {}
    if method == "kinematics" and draw(st.integers(0, 7)) == 0:
        # valid settings, extreme spans: long runs, overflowing and sub-normal time grids
        kw["t0"], kw["t_end"] = draw(st.sampled_from(
            [(0.0, 1e8), (0.0, 1e12), (0.0, 1e300), (-1e308, 1e308), (1e300, 1.0000001e300),
             (-1e300, 0.0), (0.0, 5e-324), (1e15, 1e15 + 0.25)]))
        kw["steps"] = draw(st.sampled_from([1, 2, 3]))
    elif method == "kinematics":
        kw["t_end"] = draw(TIME_ARG)
        kw["steps"] = draw(STEPS_ARG)
        if draw(st.booleans()):
            kw["t0"] = draw(TIME_ARG)
        if draw(st.booleans()):
            kw["tol"] = draw(TOL_ARG)
        if draw(st.booleans()):
            kw["maxit"] = draw(MAXIT_ARG)
        if draw(st.booleans()):
            kw["positions_only"] = draw(st.sampled_from([True, False, np.bool_(True), 1,
                                                        "yes", None, float("nan")]))
    elif method == "analyze_dof":
        kw["t"] = draw(TIME_ARG)
        kw["tol"] = draw(TOL_ARG)
    else:
        nq = 7 if "cam" in base else (3 if "door" in base else (12 if base == "gears" else 9))
        good = st.lists(SMALL_FLOATS, min_size=nq, max_size=nq)
        state = st.one_of(good, good.map(np.array), HOSTILE_ARG,
                          st.lists(SMALL_FLOATS, min_size=0, max_size=nq + 2),
                          st.builds(lambda q, i, v: q[:i] + [v] + q[i + 1:], good,
                                    st.integers(0, nq - 1), NONFINITE | EXTREME))
        kw["q"] = draw(state)
        if method == "gamma":
            kw["qd"] = draw(state)
        kw["t"] = draw(TIME_ARG)
    return base, method, kw


@hostile_settings(250)
@given(call=analysis_call())
def test_analysis_settings_and_states(call: tuple[str, str, dict[str, Any]]) -> None:
    """kinematics, analyze_dof, phi, jacobian, nu and gamma with hostile times, steps
    (10**9 among them: refused for memory before anything is allocated), tolerances,
    iteration limits and states: a ModelError naming "analysis", "state" or the model, an
    AnalysisError, an InsufficientMemoryError, or finite results; no hang, no stray
    warning."""
    _count("test_analysis_settings_and_states")
    WORKER.call("check_analysis_call", *call)


# ------------------------------------------------------------------------------------------
# 3. the private _core functions
# ------------------------------------------------------------------------------------------
def _packed(name: str) -> dict[str, Any]:
    model = from_dict(BASE[name])
    p = pack(model)
    return {"nb": p.nb, "ctab": p.ctab, "rpar": p.rpar, "neq": p.neq, "nq": p.nq, "q0": p.q0}


CORE_BASES = {n: _packed(n) for n in ["slider_crank.toml", "cam_follower.toml", "slide",
                                      "gears", "fourier_cam", "spline_cam", "weld_slot"]}
CORE_NAMES = sorted(CORE_BASES)

INT_EDGE = st.one_of(st.sampled_from([-(2**31), -(2**31) + 1, -2, -1, 0, 1, 2, 3, 4, 5, 6, 7,
                                      8, 9, 10, 11, 12, 100, 101, 102, 103, 104, 1000,
                                      2**31 - 8, 2**31 - 2, 2**31 - 1, 715827883, 10**6]),
                     st.integers(-(2**31), 2**31 - 1))
REAL_EDGE = st.one_of(st.sampled_from([np.nan, np.inf, -np.inf, 1e308, -1e308, 1e300, 1e154,
                                       5e-324, 0.0, -0.0, -1.0, 1e6, 2.5, 3.0, 1e5, 1e6 - 1]),
                      st.floats())


@st.composite
def core_tables(draw: Any, base: dict[str, Any]) -> tuple[Any, Any, Any]:
    """(nb, ctab, rpar) of a valid model, hostile in a few places."""
    nb: Any = base["nb"]
    ctab = np.array(base["ctab"], dtype=np.int32, order="F")
    rpar: Any = base["rpar"].copy()
    for _ in range(draw(st.integers(0, 3))):
        what = draw(st.sampled_from(["cell", "cell", "cell", "offset", "real", "real", "nb",
                                     "shape-ctab", "shape-rpar", "dtype"]))
        table = ctab.ndim == 2 and ctab.shape[0] == 8 and ctab.shape[1] > 0 \
            and ctab.dtype == np.int32
        nc = ctab.shape[1] if table else 0
        if what == "cell" and table:
            ctab[draw(st.integers(0, 7)), draw(st.integers(0, nc - 1))] = draw(INT_EDGE)
        elif what == "offset" and table:
            k = draw(st.integers(0, nc - 1))
            ctab[draw(st.sampled_from([5, 6])), k] = draw(INT_EDGE)
        elif what == "real" and isinstance(rpar, np.ndarray) and rpar.ndim == 1 \
                and rpar.size and rpar.dtype == np.float64:
            rpar[draw(st.integers(0, rpar.size - 1))] = draw(REAL_EDGE)
        elif what == "nb":
            nb = draw(INT_EDGE | st.sampled_from([np.nan, 2**31, 2**40, -(2**31) - 1, None,
                                                  "2", 1.5, [3]]))
        elif what == "shape-ctab" and ctab.ndim == 2:
            ctab = draw(st.sampled_from([
                ctab[:, :0], ctab[:7], np.vstack([ctab, ctab[:1]]), ctab.T.copy(), ctab[0],
                ctab[:, :1], np.ascontiguousarray(ctab), ctab[None], np.zeros((8, 0), np.int32),
                np.hstack([ctab, ctab]), ctab[:, ::-1]]))
        elif what == "shape-rpar" and isinstance(rpar, np.ndarray):
            rpar = draw(st.sampled_from([rpar[:0], rpar[:len(rpar) // 2], rpar[:-1],
                                         np.append(rpar, [1.0, 2.0]), rpar.reshape(1, -1),
                                         rpar[None, :, None], np.zeros(0), rpar[:1]]))
        elif what == "dtype":
            if draw(st.booleans()):
                if ctab.dtype == np.int32:
                    ctab = ctab.astype(draw(st.sampled_from([np.float64, np.int64, np.int8,
                                                             np.bool_, np.uint32])))
            elif isinstance(rpar, np.ndarray) and rpar.dtype == np.float64:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")      # float32 overflow is the point
                    rpar = rpar.astype(draw(st.sampled_from(
                        [np.float32, np.int64, np.complex128, np.bool_, object])))
    return nb, ctab, rpar


def _vec(draw: Any, v: np.ndarray) -> Any:
    """A copy of v, hostile in a few places or in shape."""
    v = np.array(v, dtype=float)
    how = draw(st.sampled_from(["same", "entries", "entries", "shape", "type"]))
    if how == "entries" and v.size:
        for _ in range(draw(st.integers(1, 3))):
            v[draw(st.integers(0, v.size - 1))] = draw(REAL_EDGE)
    elif how == "shape":
        return draw(st.sampled_from([v[:0], v[:-1], np.append(v, 0.0), v.reshape(1, -1),
                                     np.tile(v, 2)]))
    elif how == "type":
        return draw(st.sampled_from([None, "q", [list(v)], v.astype(np.complex128),
                                     v.astype(object), float(v[0]) if v.size else 0.0]))
    return v


SCALAR_EDGE = REAL_EDGE | st.sampled_from([None, "0.1", [0.1], 10**400, True])


@hostile_settings(300)
@given(data=st.data())
def test_core_sizes_hostile(data: st.DataObject) -> None:
    """core_sizes with out-of-range bodies, kinds, sub-kinds, parameter offsets and lengths,
    NaN and infinite parameters, wrong table shapes and types."""
    _count("test_core_sizes_hostile")
    base = CORE_BASES[data.draw(st.sampled_from(CORE_NAMES), label="base")]
    nb, ctab, rpar = data.draw(core_tables(base), label="tables")
    WORKER.call("check_core", "core_sizes", (nb, ctab, rpar))


@hostile_settings(300)
@given(data=st.data())
def test_core_eval_hostile(data: st.DataObject) -> None:
    """core_eval with NaN, infinite or huge q, q_dot and t, a wrong neq, wrong-size states
    and hostile tables: status 0 only with finite Phi, J, nu and gamma."""
    _count("test_core_eval_hostile")
    base = CORE_BASES[data.draw(st.sampled_from(CORE_NAMES), label="base")]
    nb, ctab, rpar = data.draw(core_tables(base) if data.draw(st.booleans())
                               else st.just((base["nb"], base["ctab"], base["rpar"])),
                               label="tables")
    neq = data.draw(st.sampled_from([base["neq"]] * 4 + [base["neq"] - 1, base["neq"] + 1, 0,
                                                         -1, 2**31, None]), label="neq")
    q = _vec(data.draw, base["q0"])
    qd = _vec(data.draw, np.zeros(base["nq"]))
    t = data.draw(SCALAR_EDGE | st.just(0.0), label="t")
    WORKER.call("check_core", "core_eval", (nb, ctab, rpar, neq, q, qd, t))


@hostile_settings(250)
@given(data=st.data())
def test_core_kinematics_hostile(data: st.DataObject) -> None:
    """core_kinematics with NaN, infinite or huge q0, times, tolerance, iteration limit and
    singular-time resolution, negative or overflowing step counts and hostile tables: status
    0 only with finite outputs; no crash, no hang."""
    _count("test_core_kinematics_hostile")
    base = CORE_BASES[data.draw(st.sampled_from(CORE_NAMES), label="base")]
    nb, ctab, rpar = data.draw(core_tables(base) if data.draw(st.booleans())
                               else st.just((base["nb"], base["ctab"], base["rpar"])),
                               label="tables")
    neq = data.draw(st.sampled_from([base["neq"]] * 4 + [base["neq"] - 1, 0, -1]), label="neq")
    q0 = _vec(data.draw, base["q0"])
    t0 = data.draw(st.just(0.0) | SCALAR_EDGE, label="t0")
    t1 = data.draw(st.sampled_from([0.1, 0.1, 1e8, 1e12, 1e300, np.nan, np.inf, 0.0, -0.1])
                   | SCALAR_EDGE, label="t1")
    nsteps = data.draw(st.sampled_from([2, 2, 0, 1, 3, -1, -2, -(2**31), 2**31 - 1, 2**31,
                                        None, 2.5]), label="nsteps")
    tol = data.draw(st.sampled_from([0.0, 0.0, np.nan, np.inf, -1.0, 1e300, 1e-300, 1.0])
                    | REAL_EDGE, label="tol")
    maxit = data.draw(st.sampled_from([0, 0, -1, 1, 3, 2**31 - 1, -(2**31)]), label="maxit")
    tmin = data.draw(st.sampled_from([0.0, 0.0, np.nan, np.inf, -1.0, 1e300, 5e-324])
                     | REAL_EDGE, label="tmin")
    every = data.draw(st.sampled_from([1, 1, 1, 2, 3, 0, -1, 2**31 - 1]), label="every")
    solver = data.draw(st.sampled_from([0, 0, 1, 2, 3, -1]), label="solver")
    # the output columns the core expects, or a wrong count (kept small: f2py allocates it)
    right = (nsteps // every + 1 + (nsteps % every > 0)
             if isinstance(nsteps, int) and 0 <= nsteps <= 100 and every >= 1 else 3)
    nout = data.draw(st.sampled_from([right, right, right, right + 1, right - 1, 0, -1]),
                     label="nout")
    WORKER.call("check_core", "core_kinematics",
                (nb, ctab, rpar, neq, q0, t0, t1, nsteps, tol, maxit, tmin, every, solver, nout))


@hostile_settings(250)
@given(data=st.data())
def test_core_analyze_hostile(data: st.DataObject) -> None:
    """core_analyze with NaN, infinite or huge q0, t and tolerance and hostile tables."""
    _count("test_core_analyze_hostile")
    base = CORE_BASES[data.draw(st.sampled_from(CORE_NAMES), label="base")]
    nb, ctab, rpar = data.draw(core_tables(base) if data.draw(st.booleans())
                               else st.just((base["nb"], base["ctab"], base["rpar"])),
                               label="tables")
    neq = data.draw(st.sampled_from([base["neq"]] * 4 + [base["neq"] + 1, 0, -1]), label="neq")
    q0 = _vec(data.draw, base["q0"])
    t = data.draw(st.just(0.0) | SCALAR_EDGE, label="t")
    tol = data.draw(st.just(0.0) | REAL_EDGE, label="tol")
    WORKER.call("check_core", "core_analyze", (nb, ctab, rpar, neq, q0, t, tol))


PROFILE_RAW = [np.array([0.4, 0.0, 1.0]),
               np.array([4.0, 1.0, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0, -1.0]),
               np.array([0.0, 0.0, 2.0, 1.0, 0.1, 0.1, 0.05, 0.0])]


@hostile_settings(300)
@given(data=st.data())
def test_core_profile_hostile(data: st.DataObject) -> None:
    """core_profile with unknown kinds, malformed, NaN or infinite parameters, point counts
    that do not match, and NaN, infinite or huge alpha: status 0 only with finite points."""
    _count("test_core_profile_hostile")
    kind = data.draw(st.sampled_from([1, 2, 3]) | INT_EDGE, label="kind")
    raw = _vec(data.draw, PROFILE_RAW[data.draw(st.integers(0, 2), label="raw")])
    alpha = _vec(data.draw, np.linspace(0.0, 2 * np.pi, data.draw(st.integers(0, 9))))
    WORKER.call("check_core", "core_profile", (kind, raw, alpha))
