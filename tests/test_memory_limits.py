"""Large models and failed allocations: a typed error, never a dead process.

Each case runs in its own Python process (a crash, a runtime abort of the Fortran library or
an out-of-memory kill is seen as its exit status), most under an address-space limit
(``RLIMIT_AS``) so that no test can eat the machine's memory.

Oracles: the N-four-bar's closed form (every crank turns with the driver, theta = pi/2 - t;
the couplers translate), the peak resident memory of the process (``ru_maxrss``), and for the
allocation failures only the documented behaviour (``InsufficientMemoryError``, a
``MemoryError``, naming the size asked).
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import mbd2d

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"

PRELUDE = f"""
import json, math, resource, sys
sys.path.insert(0, {str(EX)!r})
import numpy as np
import mbd2d
from nfourbar import build

def vm_bytes():
    for line in open("/proc/self/status"):
        if line.startswith("VmSize:"):
            return int(line.split()[1]) * 1024

def limit(extra_mib):
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    resource.setrlimit(resource.RLIMIT_AS, (vm_bytes() + extra_mib * 2**20, hard))
    return soft, hard

def unlimit(old):
    resource.setrlimit(resource.RLIMIT_AS, old)

def outcome(call):
    try:
        call()
        return ["ok", ""]
    except mbd2d.InsufficientMemoryError as e:
        return ["InsufficientMemoryError", str(e)]
    except MemoryError as e:
        return ["MemoryError", str(e)]
    except Exception as e:
        return [type(e).__name__, str(e)]
"""


def run_child(body: str, timeout: float = 240.0) -> dict:
    """Run PRELUDE + body in a fresh interpreter; the body prints one JSON line last."""
    code = PRELUDE + textwrap.dedent(body)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=timeout)
    assert r.returncode == 0, (f"the process died (exit {r.returncode}, a negative code is "
                               f"a signal): {r.stderr[-3000:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_ten_thousand_loop_kinematics_runs_banded_in_little_memory() -> None:
    """N = 10000 (60,003 coordinates): once a 28.8 GB dense J and a dead process, now the
    band path, no n x n array: peak RSS of the whole process well under 400 MiB."""
    out = run_child("""
        n = 10000
        model = build(n)
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        old = limit(2048)              # far below the dense J: any n x n array would fail
        res = model.kinematics(t_end=0.3, steps=3)
        unlimit(old)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        print(json.dumps({"t": res.t.tolist(), "q": res.q.tolist(), "qd": res.qd.tolist(),
                          "qdd": res.qdd.tolist(), "solver": res.stats["solver"],
                          "peak_mib": peak / 1024, "before_mib": before / 1024}))
    """)
    assert out["solver"] == "banded"
    assert out["peak_mib"] < 400, out["peak_mib"]
    t = np.array(out["t"])
    q, qd, qdd = (np.array(out[k]) for k in ("q", "qd", "qdd"))
    n = 10000
    th = np.pi / 2 - t[:, None]
    # cranks k = 0..n (bodies 0..n), couplers after them: x = k + cos(th)/2, y = sin(th)/2
    k = np.arange(n + 1)[None, :]
    np.testing.assert_allclose(q[:, 2:3 * (n + 1):3], np.broadcast_to(th, (len(t), n + 1)),
                               rtol=0, atol=1e-11)
    np.testing.assert_allclose(q[:, 0:3 * (n + 1):3], k + 0.5 * np.cos(th), rtol=0, atol=1e-11)
    np.testing.assert_allclose(q[:, 1:3 * (n + 1):3], 0.5 * np.sin(th) + 0 * k, rtol=0,
                               atol=1e-11)
    np.testing.assert_allclose(qd[:, 2:3 * (n + 1):3], -1.0, rtol=0, atol=1e-10)
    np.testing.assert_allclose(qdd[:, 2:3 * (n + 1):3], 0.0, rtol=0, atol=1e-9)
    # couplers: x = k + 1/2 + cos(th), y = sin(th), theta = 0
    kc = np.arange(n)[None, :]
    c0 = 3 * (n + 1)
    np.testing.assert_allclose(q[:, c0::3], kc + 0.5 + np.cos(th), rtol=0, atol=1e-11)
    np.testing.assert_allclose(q[:, c0 + 1::3], np.sin(th) + 0 * kc, rtol=0, atol=1e-11)
    np.testing.assert_allclose(q[:, c0 + 2::3], 0.0, rtol=0, atol=1e-11)


def test_a_failed_dense_allocation_is_a_typed_error() -> None:
    """The dense J of 11,403 coordinates (1 GB) under a 400 MiB address-space allowance: the
    allocation fails inside the core, which returns a status; the process lives on and can
    run again once the limit is lifted."""
    out = run_child("""
        model = build(1900)
        old = limit(400)
        first = outcome(lambda: model.kinematics(t_end=0.1, steps=2, solver="dense"))
        unlimit(old)
        again = outcome(lambda: build(3).kinematics(t_end=0.1, steps=2))
        print(json.dumps({"first": first, "again": again}))
    """)
    kind, text = out["first"]
    assert kind == "InsufficientMemoryError", out
    assert "11403 x 11403" in text and "996.2 MiB" in text, text
    assert "banded" in text, text                      # what to change
    assert out["again"][0] == "ok"
    assert issubclass(mbd2d.InsufficientMemoryError, MemoryError)
    assert issubclass(mbd2d.InsufficientMemoryError, mbd2d.MbdError)


def test_every_allocation_of_the_band_path_fails_cleanly() -> None:
    """Address-space allowances from 1 MiB up to enough: each run of N = 10000 kinematics
    ends in success or a MemoryError (the core's typed one, or NumPy's for the arrays
    Python allocates), never an abort; at least one failure is the core's."""
    out = run_child("""
        model = build(10000)
        res = {}
        for mib in (1, 4, 8, 12, 16, 24, 32, 48, 256):
            old = limit(mib)
            res[mib] = outcome(lambda: model.kinematics(t_end=0.01, steps=3))
            unlimit(old)
        print(json.dumps(res))
    """)
    kinds = {k: v[0] for k, v in out.items()}
    assert set(kinds.values()) <= {"ok", "InsufficientMemoryError", "MemoryError"}, out
    assert "InsufficientMemoryError" in kinds.values(), out
    assert kinds["256"] == "ok", out
    for kind, text in out.values():
        if kind == "InsufficientMemoryError":
            assert "MiB" in text and "allocating" in text, text


def test_huge_model_dynamics_statics_and_inverse_run_banded_in_little_memory() -> None:
    """N = 10000 (60,003 coordinates): dynamics, statics and inverse dynamics once needed
    hundreds of GB of dense matrices and refused; now (solver="auto") they take the band
    path, no n x n array: generalized-alpha and dopri5 for a few steps, the equilibrium and
    the multipliers, inverse dynamics' and statics' sensitivities (the motor torque's to
    gravity against its closed form) and the rank analysis of analyze_dof, all under a
    1 GiB address-space limit (a missed n x n allocation fails
    the test instead of filling the machine), peak RSS of the whole process under 400 MiB
    (measured 215 MiB). Oracle for the motion: the parallelogram branch (every crank at the
    same angle, the couplers level). solver="dense" keeps n x n matrices and refuses at
    once, naming the size and the band path."""
    out = run_child("""
        model = build(10000, driven=False, omega0=1.0)     # 1 kg bars, free
        driven = build(10000, omega0=1.0)                   # the same, driven
        old = limit(1024)
        res = {}
        def dyn(method, **kw):
            r = model.dynamics(t_end=0.002, steps=2, method=method, **kw)
            th = r.q[:, 2::3][:, :10001]                   # the crank angles
            yc = r.q[:, 3 * 10001 + 1::3]                   # the couplers' heights
            res[method] = [r.stats["solver"], float(np.abs(th - th[:, :1]).max()),
                           float(np.abs(yc - yc[:, :1]).max())]
        def st():
            s = model.statics()
            res["statics"] = [s.stats["solver"], s.stability, s.residual]
        def inv():
            r = driven.inverse_dynamics(t_end=0.002, steps=2)
            tau = (10001 / 2 + 10000) * 9.81 * np.cos(r.body("crank0").theta)
            res["inverse"] = [r.stats["multiplier_solver"],
                              float(np.abs(r.effort("motor") - tau).max() / np.abs(tau).max())]
        def inv_sens():
            r = driven.inverse_dynamics(t_end=0.002, steps=2, sensitivities=["model.gravity.1"])
            c = 10001 / 2 + 10000                       # d tau / d g_y = -c cos(theta)
            want = -c * np.cos(r.body("crank0").theta)
            res["inverse_sens"] = [r.stats["multiplier_solver"],
                                   float(np.abs(r.effort_dp("motor")[:, 0] - want).max()
                                         / np.abs(want).max())]
        def st_sens():
            s = model.statics(sensitivities=["model.gravity.1"])
            res["statics_sens"] = [s.stats["solver"], float(np.abs(s.dq_dp).max())]
        def dof():
            d = model.analyze_dof()
            res["dof"] = [d.rank, d.dof, d.mobility, len(d.redundant_rows)]
        res["outcomes"] = [outcome(lambda: dyn("generalized-alpha", h=1e-3)),
                           outcome(lambda: dyn("dopri5")), outcome(st), outcome(inv),
                           outcome(inv_sens), outcome(st_sens), outcome(dof)]
        # solver="dense" keeps n x n matrices: refused at once, naming the size
        res["dense"] = [outcome(lambda: model.dynamics(t_end=0.01, steps=2, solver="dense")),
                        outcome(lambda: model.statics(solver="dense")),
                        outcome(lambda: driven.inverse_dynamics(t_end=0.01, steps=2,
                                                                solver="dense"))]
        unlimit(old)
        res["rss_mib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        print(json.dumps(res))
    """)
    assert [k for k, _ in out["outcomes"]] == ["ok"] * 7, out["outcomes"]
    for method in ("generalized-alpha", "dopri5"):
        solver, spread, level = out[method]
        assert solver == "banded"
        assert spread < 1e-9 and level < 1e-9, out[method]     # cranks parallel, couplers level
    assert out["statics"][0] == "banded" and out["statics"][1] == "unstable"   # upright
    assert out["statics"][2] < 1e-12                                          # measured 1e-18
    # the motor torque against its closed form (test_band_dynamics): it was 99.98% off here
    # (the multipliers' band solve took the index-1 check's regularized least squares)
    assert out["inverse"][0] == "banded" and out["inverse"][1] < 1e-8, out["inverse"]
    # the sensitivities and the rank analysis on the band path too (they were dense: refused)
    assert out["inverse_sens"][0] == "banded" and out["inverse_sens"][1] < 1e-9
    assert out["statics_sens"][0] == "banded" and out["statics_sens"][1] < 1e-6
    assert out["dof"] == [60002, 1, 1, 0]
    assert out["rss_mib"] < 400, out["rss_mib"]
    for kind, text in out["dense"]:
        assert kind == "InsufficientMemoryError", (kind, text)
        assert re.search(r"the dense dynamics \(6000[23] equations, 60003 coordinates\) would "
                         r"need [0-9.]+ GiB", text), text
        assert "fewer coordinates" in text and 'solver="banded"' in text, text


def test_banded_singular_report_agrees_with_the_dense_svd() -> None:
    """The band path diagnoses a dead centre without a dense J (inverse and power iteration
    on the band factors); the dense path by the SVD. Same time, driver, dependent
    constraints, and sigma_min / sigma_max within a few per cent."""
    model = mbd2d.load(EX / "fourbar_seed.toml")
    got = {}
    for solver in ("dense", "banded"):
        with pytest.raises(mbd2d.SingularConfigurationError) as ei:
            model.kinematics(t_end=2.0, steps=200, solver=solver)
        e = ei.value
        got[solver] = (e.t, e.driver, e.dependent, e.sigma_min / e.sigma_max)
    d, b = got["dense"], got["banded"]
    assert abs(d[0] - b[0]) < 1e-9 and d[1] == b[1] == "motor" and d[2] == b[2]
    assert abs(b[3] / d[3] - 1) < 0.05, (d[3], b[3])


MALLOC_COUNTER = r"""
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
static long n_malloc = 0;
static void *(*real_malloc)(size_t) = 0;
void *malloc(size_t s) {
  if (!real_malloc) real_malloc = (void *(*)(size_t)) dlsym(RTLD_NEXT, "malloc");
  n_malloc++;
  return real_malloc(s);
}
__attribute__((destructor)) static void report(void) {
  fprintf(stderr, "MALLOC_COUNT %ld\n", n_malloc);
}
"""


def test_the_kinematic_loop_allocates_nothing_per_step(tmp_path: Path) -> None:
    """mbd2d-solve under a malloc counter (LD_PRELOAD): 10x the steps, the same number of
    allocations, on the dense path (four-bar) and the band path (N-four-bar, 75 coordinates).
    Before: one heap temporary per step or Newton iteration (an array expression passed as
    an argument, an automatic array)."""
    from test_standalone import find_solver
    sys.path.insert(0, str(EX))
    from nfourbar import build
    cc = shutil.which("cc") or shutil.which("gcc")
    assert cc, "the C compiler that built the package"
    src = tmp_path / "count.c"
    src.write_text(MALLOC_COUNTER)
    lib = tmp_path / "count.so"
    subprocess.run([cc, "-O2", "-shared", "-fPIC", str(src), "-o", str(lib), "-ldl"],
                   check=True, capture_output=True)
    solver = find_solver()
    models = {"dense": mbd2d.load(EX / "fourbar_grashof.toml"), "banded": build(12)}
    for path, model in models.items():
        counts = []
        for steps in (100, 1000):
            f = tmp_path / f"{path}.mbd"
            model.export(f, t_end=1.0, steps=steps)
            r = subprocess.run([solver, str(f), str(tmp_path / "o.csv")], capture_output=True,
                               text=True, timeout=60, env={**os.environ, "LD_PRELOAD": str(lib)})
            assert r.returncode == 0, r.stderr
            counts.append(int(r.stderr.split("MALLOC_COUNT")[-1]))
        assert counts[0] == counts[1], (path, counts)


@pytest.mark.parametrize("method, settings", [
    ("dopri5", {"rtol": 1e-8, "atol": 1e-8}),
    ("partitioned", {"rtol": 1e-8, "atol": 1e-8}),
    ("generalized-alpha", {"rtol": 1e-6}),
    ("generalized-alpha", {"h": 1e-3}),
    ("baumgarte-rk4", {"h": 1e-3}),
    ("dopri5", {"rtol": 1e-8, "atol": 1e-8, "sensitivities": ["body.coupler.mass",
                                                              "model.gravity.1"]}),
    ("generalized-alpha", {"rtol": 1e-6, "sensitivities": ["body.coupler.mass",
                                                           "model.gravity.1"]}),
    ("generalized-alpha", {"h": 1e-3, "sensitivities": ["body.coupler.mass"]}),
])
def test_the_dynamics_loop_allocates_nothing_per_step(tmp_path: Path, method: str,
                                                      settings: dict) -> None:
    """The dynamics under the malloc counter: a free four-bar over 1 s and over 4 s (about
    4x the steps), two output intervals so that the outputs are few; the same number of
    allocations (with design sensitivities too: dopri5's variational equations and
    generalized-alpha's differentiated steps).
    Before: partitioned allocated about 60 times per step (vector subscripts, an array
    function, automatic arrays, stage expressions passed as arguments), error-controlled
    generalized-alpha once per step."""
    from test_standalone import find_solver
    sys.path.insert(0, str(ROOT / "bench"))
    from models import free_fourbar
    cc = shutil.which("cc") or shutil.which("gcc")
    assert cc, "the C compiler that built the package"
    src = tmp_path / "count.c"
    src.write_text(MALLOC_COUNTER)
    lib = tmp_path / "count.so"
    subprocess.run([cc, "-O2", "-shared", "-fPIC", str(src), "-o", str(lib), "-ldl"],
                   check=True, capture_output=True)
    solver = find_solver()
    model = free_fourbar()
    counts, steps = [], []
    for t_end in (1.0, 4.0):
        f = tmp_path / "dyn.mbd"
        model.export(f, t_end=t_end, steps=2, analysis="dynamics", method=method, **settings)
        r = subprocess.run([solver, str(f), str(tmp_path / "o.csv")], capture_output=True,
                           text=True, timeout=120, env={**os.environ, "LD_PRELOAD": str(lib)})
        assert r.returncode == 0, r.stderr
        counts.append(int(r.stderr.split("MALLOC_COUNT")[-1]))
        steps.append(model.dynamics(t_end=t_end, steps=2, method=method,
                                    **settings).stats["steps"])
    assert steps[1] > 2 * steps[0] > 0, steps
    assert counts[0] == counts[1], (method, counts, steps)
