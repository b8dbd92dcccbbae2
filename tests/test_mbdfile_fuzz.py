"""mbd2d-solve against mutated model files: whatever the file holds, the program ends with a
documented exit code (0 ok, 2 bad input, 3 singular configuration, 4 other numerical failure)
and, for a failure, a message of its own on standard error; never a signal, a runtime error
of the Fortran library or another code, and never a run that outgrows the memory.

The files are real exports (``Model.export``) of the examples, mutated by a seeded random
generator: truncations, huge, negative and mismatched counts, garbage lines, deleted and
repeated lines, byte flips, and NaN, infinite or out-of-range numbers. Each file runs in its
own process with a timeout. ``MBD2D_FUZZ_EXAMPLES`` sets the number of files per mutation
kind (default 25, which keeps this file to a few seconds).
"""
from __future__ import annotations

import math
import os
import random
import subprocess
import sys
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

import mbd2d
from test_standalone import find_solver

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
sys.path.insert(0, str(EX))
from nfourbar import build as nfourbar  # noqa: E402

N_PER_KIND = int(os.environ.get("MBD2D_FUZZ_EXAMPLES", "25"))
TIMEOUT = 30.0
CODES = {0, 2, 3, 4}
EXAMPLES = ["fourbar_grashof", "fourbar_seed", "fourbar_redundant", "slider_crank",
            "cam_follower", "door_two_hinges", "parallelogram_extra_link"]
COUNT_KEYS = ("bodies", "constraints", "params", "steps", "maxit", "every", "labels", "forces",
              "fparams", "max_steps", "sensitivities", "opens", "measures")
# (no counts that are valid and merely large: 1e9 steps need 216 GB of outputs and more)
HUGE = [-1, -7, -2**31, -2**31 - 1, 2**31 - 1, 2**31, 2**32 + 1, 10**9, 10**9 + 1, 10**10,
        10**12, 2**63 - 1, 2**63, 10**19, 10**30]
BAD_REALS = ["nan", "NaN", "-nan", "inf", "-inf", "Infinity", "1e309", "-1e309", "1e-400",
             "1.0e+300", "-1.0e+300", "1e30", "0x1p3", "1/2", "3*2", "1,5", "--1", "1e", ""]


@pytest.fixture(scope="module")
def solver() -> str:
    return find_solver()


@pytest.fixture(scope="module")
def bases(tmp_path_factory: pytest.TempPathFactory) -> list[bytes]:
    """Exports of the examples (and a banded N-four-bar) as the files to mutate."""
    d = tmp_path_factory.mktemp("bases")
    models = [mbd2d.load(EX / f"{name}.toml") for name in EXAMPLES] + [nfourbar(12)]
    out = []
    for k, model in enumerate(models):
        f = d / f"base{k}.mbd"
        model.export(f, t_end=1.0, steps=40)
        out.append(f.read_bytes())
    # every analysis of format 2, with masses, forces, settings and output columns
    heavy = mbd2d.load(EX / "fourbar_masses.toml")
    swing = mbd2d.load(EX / "pendulum_spring.toml")
    cols = ["energy", "multipliers", "reactions", "efforts"]
    for k, (model, kw) in enumerate([
            (heavy, {"analysis": "inverse-dynamics", "t_end": 1.0, "steps": 40,
                     "outputs": cols}),
            (swing, {"analysis": "dynamics", "t_end": 1.0, "steps": 40,
                     "method": "generalized-alpha", "h": 1e-3, "outputs": cols}),
            (heavy, {"analysis": "dynamics", "t_end": 0.5, "steps": 20, "rtol": 1e-7}),
            (swing, {"analysis": "statics", "outputs": ["multipliers", "reactions"]}),
            # design sensitivities: the block, and the columns of each analysis
            (heavy, {"analysis": "inverse-dynamics", "t_end": 1.0, "steps": 20,
                     "outputs": cols, "sensitivities": ["joint.B.points.0.0",
                                                        "body.coupler.mass",
                                                        "model.gravity.1"]}),
            (heavy, {"analysis": "dynamics", "t_end": 0.2, "steps": 10,
                     "sensitivities": ["body.crank.inertia"]}),
            (swing, {"analysis": "statics", "outputs": ["reactions", "efforts"],
                     "sensitivities": ["body.bar.mass", "force.torsion.angle0"]}),
            # measure columns: every recipe kind
            (heavy, {"analysis": "inverse-dynamics", "t_end": 1.0, "steps": 20,
                     "measures": ["transmission_angle:B", "velocity_ratio:motor:rocker.theta",
                                  "mechanical_advantage:motor:rocker.theta",
                                  "dead_centre_distance"]})]):
        f = d / f"dyn{k}.mbd"
        model.export(f, **kw)
        out.append(f.read_bytes())
    # modes: the damped table, a count about q0, and a sweep of them
    car = mbd2d.load(EX / "half_car.toml")
    for k, (model, kw) in enumerate([(swing, {"outputs": ["damped"]}),
                                     (car, {"count": 2, "equilibrium": False})]):
        f = d / f"modes{k}.mbd"
        model.export(f, analysis="modes", **kw)
        out.append(f.read_bytes())
    # frf: two inputs (a damper's free length and gravity), log-spaced frequencies
    f = d / "frf.mbd"
    car.export(f, analysis="frf", inputs=["force.front_suspension.length0", "model.gravity.1"],
               frequencies=np.geomspace(0.1, 30.0, 9))
    out.append(f.read_bytes())
    f = d / "linearize.mbd"                   # a state-space system of the same inputs
    car.export(f, analysis="linearize",
               inputs=["force.front_suspension.length0", "model.gravity.1"],
               outputs=["velocities"])
    out.append(f.read_bytes())
    f = d / "modes_sweep.mbd"
    mbd2d.export_sweep(car, f, {"force.front_suspension.damping": [0.0, 1500.0],
                                "body.rear_wheel.mass": [35.0, 0.0]}, "modes", count=3)
    out.append(f.read_bytes())
    f = d / "frf_sweep.mbd"
    mbd2d.export_sweep(car, f, {"force.front_suspension.damping": [0.0, 1500.0],
                                "body.rear_wheel.mass": [35.0, 0.0]}, "frf",
                       inputs=["force.front_tyre.points.0.1"], frequencies=[0.0, 1.2, 9.0])
    out.append(f.read_bytes())
    # sweeps: the cases and opens blocks (a kinematic grid, an inverse dynamics sweep)
    for k, (model, cases, analysis, kw) in enumerate([
            (mbd2d.load(EX / "fourbar_grashof.toml"),
             mbd2d.grid({"joint.B.points.0.0": [1.6, 1.8], "joint.O4.points.1.0": [2.9, 3.1]}),
             "kinematics", {"t_end": 1.0, "steps": 20}),
            (heavy, {"body.coupler.mass": [1.0, 2.0, 3.0]}, "inverse_dynamics",
             {"t_end": 0.5, "steps": 10}),
            # a sweep with measures (angle lines naming their points' entries) and
            # design sensitivities
            (heavy, {"joint.B.points.1.0": [-1.3, -1.2]}, "inverse_dynamics",
             {"t_end": 0.5, "steps": 10, "measures": ["transmission_angle:B",
                                                      "velocity_ratio:motor:rocker.theta"],
              "sensitivities": ["body.rocker.mass", "joint.O4.points.1.0"]})]):
        f = d / f"sweep{k}.mbd"
        mbd2d.export_sweep(model, f, cases, analysis, **kw)
        out.append(f.read_bytes())
    return out


def _lines(data: bytes) -> list[bytes]:
    return data.split(b"\n")


def _data_line_indices(lines: list[bytes]) -> list[int]:
    return [i for i, ln in enumerate(lines) if ln.strip() and not ln.lstrip().startswith(b"#")]


def truncate(rng: random.Random, data: bytes) -> bytes:
    """Cut the file anywhere (often inside a number or a block)."""
    return data[:rng.randrange(len(data))]


def bad_count(rng: random.Random, data: bytes) -> bytes:
    """A count (bodies, constraints, params, steps, maxit) huge, negative or off by some."""
    lines = _lines(data)
    idx = [i for i, ln in enumerate(lines) if ln.split()[:1] and
           ln.split()[0].decode(errors="replace") in COUNT_KEYS]
    i = rng.choice(idx)
    key, value = lines[i].split()[:2]
    n = int(value)
    new = rng.choice(HUGE + [n + 1, n - 1, n + rng.randint(2, 50), 3 * n, -n, 0])
    lines[i] = key + b" " + str(new).encode()
    return b"\n".join(lines)


def garbage_line(rng: random.Random, data: bytes) -> bytes:
    """A line of printable or arbitrary bytes inserted anywhere."""
    lines = _lines(data)
    k = rng.randrange(len(lines) + 1)
    if rng.random() < 0.5:
        alphabet = "abcdefghijklmnopqrstuvwxyz0123456789 .-+e,/*'\"\t"
        junk = "".join(rng.choice(alphabet) for _ in range(rng.randint(1, 60))).encode()
    else:
        junk = bytes(rng.randrange(256) for _ in range(rng.randint(1, 60))).replace(b"\n", b"")
    if rng.random() < 0.2:
        junk = junk * rng.randint(100, 200)          # also lines longer than the reader's limit
    lines.insert(k, junk)
    return b"\n".join(lines)


def edit_lines(rng: random.Random, data: bytes) -> bytes:
    """A data line deleted, repeated, or two swapped."""
    lines = _lines(data)
    idx = _data_line_indices(lines)
    i, j = rng.choice(idx), rng.choice(idx)
    what = rng.randrange(3)
    if what == 0:
        del lines[i]
    elif what == 1:
        lines.insert(i, lines[i])
    else:
        lines[i], lines[j] = lines[j], lines[i]
    return b"\n".join(lines)


def byte_flips(rng: random.Random, data: bytes) -> bytes:
    """One to five bytes flipped anywhere (comments, keywords, digits, signs, exponents)."""
    b = bytearray(data)
    idx = _data_line_indices(_lines(data))
    starts = [sum(len(ln) + 1 for ln in _lines(data)[:i]) for i in idx]
    for _ in range(rng.randint(1, 5)):
        pos = rng.randrange(starts[0], len(b)) if rng.random() < 0.9 else rng.randrange(len(b))
        b[pos] ^= rng.randrange(1, 256)
    return bytes(b)


def bad_number(rng: random.Random, data: bytes) -> bytes:
    """A real number (time, tolerance, estimate, parameter) or an integer entry replaced by NaN,
    infinity, an overflowing or malformed number, or a huge or negative integer."""
    lines = _lines(data)
    idx = _data_line_indices(lines)
    for _ in range(100):
        i = rng.choice(idx)
        toks = lines[i].split()
        slots = [k for k, t in enumerate(toks) if t[:1] in b"0123456789-+."]
        if slots:
            k = rng.choice(slots)
            if b"." in toks[k] or b"e" in toks[k]:
                toks[k] = rng.choice(BAD_REALS).encode()
            else:
                toks[k] = str(rng.choice(HUGE + [0, -1, 99])).encode()
            lines[i] = b" ".join(toks)
            break
    return b"\n".join(lines)


MUTATIONS: dict[str, Callable[[random.Random, bytes], bytes]] = {
    "truncate": truncate, "bad_count": bad_count, "garbage_line": garbage_line,
    "edit_lines": edit_lines, "byte_flips": byte_flips, "bad_number": bad_number}


def run(solver: str, path: Path, out: Path) -> subprocess.CompletedProcess:
    return subprocess.run([solver, str(path), str(out)], capture_output=True, timeout=TIMEOUT)


def check(r: subprocess.CompletedProcess, path: Path) -> None:
    """A documented exit code, and for a failure the program's own message on stderr."""
    err = r.stderr.decode(errors="replace")
    assert r.returncode in CODES, (
        f"{path}: exit code {r.returncode} (negative: killed by signal {-r.returncode}); "
        f"stderr: {err[-2000:]}")
    if r.returncode != 0:
        assert err.startswith("mbd2d-solve: ") and len(err.strip()) > len("mbd2d-solve:"), (
            f"{path}: exit {r.returncode} without a message of mbd2d-solve: {err[-2000:]!r}")
        assert "Error termination" not in err and "Backtrace" not in err, err


@pytest.mark.parametrize("kind", sorted(MUTATIONS))
def test_mutated_files(kind: str, solver: str, bases: list[bytes], tmp_path: Path) -> None:
    rng = random.Random(f"mbd2d-fuzz-{kind}")
    codes: dict[int, int] = {}
    for n in range(N_PER_KIND):
        data = MUTATIONS[kind](rng, rng.choice(bases))
        path = tmp_path / f"{kind}-{n}.mbd"
        path.write_bytes(data)
        try:
            r = run(solver, path, tmp_path / "out.csv")
        except subprocess.TimeoutExpired:
            pytest.fail(f"{path}: no answer within {TIMEOUT} s")
        check(r, path)
        codes[r.returncode] = codes.get(r.returncode, 0) + 1
        path.unlink()
    # the mutations reach the reader's checks, not only the happy path
    assert codes.get(2, 0) > 0, codes


def _too_many_steps() -> int:
    """Steps whose outputs (27 numbers each for the four-bar) exceed half the physical memory:
    1e8 (the reported case) on machines up to 36 GB."""
    phys = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    return max(100_000_000, math.ceil(0.6 * phys / (8 * 27)))


@pytest.mark.parametrize("key, value, needle", [
    ("steps", _too_many_steps(), "give fewer steps"),    # 1e8 was: 21 GB, killed after 353 s
    ("steps", 2**31 - 1, "steps must be a whole number from 1 to 1000000000"),   # was: exit 1
    ("steps", 0, "steps must be a whole number from 1"),
    ("steps", -5, "steps must be a whole number from 1"),
    ("bodies", 2**31 - 1, "more body lines than the file has left"),            # was: exit 1
    ("bodies", 0, "the body count must be at least 1"),
    ("constraints", 10**6, "more constraint lines than the file has left"),
    ("params", 10**9, "more parameters than the rest of the file can hold"),
    ("maxit", 10**7, "maxit must be a whole number from 0"),
])
def test_counts_from_the_issue(key: str, value: int, needle: str, solver: str,
                               tmp_path: Path) -> None:
    """The reported counts end with exit 2 and a message naming the file, line and count."""
    base = tmp_path / "base.mbd"
    mbd2d.load(EX / "fourbar_grashof.toml").export(base, t_end=1.0, steps=200)
    lines = base.read_text().splitlines()
    line = next(i for i, ln in enumerate(lines) if ln.split()[:1] == [key])
    lines[line] = f"{key} {value}"
    f = tmp_path / "bad.mbd"
    f.write_text("\n".join(lines) + "\n")
    r = run(solver, f, tmp_path / "o.csv")
    err = r.stderr.decode()
    assert r.returncode == 2, err
    assert err.startswith(f"mbd2d-solve: {f}:{line + 1}: "), err
    assert needle in err, err
    if needle == "give fewer steps":
        # 3 x 9 numbers x (steps + 1) times: the size asked is named
        size = 8 * 27 * (value + 1) / 2**30
        assert f"{size:.1f} GiB" in err, err
        assert not (tmp_path / "o.csv").exists()


def test_non_finite_numbers_name_their_line(solver: str, tmp_path: Path) -> None:
    base = tmp_path / "base.mbd"
    mbd2d.load(EX / "slider_crank.toml").export(base, t_end=1.0, steps=10)
    lines = base.read_text().splitlines()
    for key in ("t0", "t_end", "tol"):
        for bad in ("nan", "inf", "-Infinity", "1e999"):
            i = next(k for k, ln in enumerate(lines) if ln.split()[:1] == [key])
            mutated = lines.copy()
            mutated[i] = f"{key} {bad}"
            f = tmp_path / "bad.mbd"
            f.write_text("\n".join(mutated) + "\n")
            r = run(solver, f, tmp_path / "o.csv")
            err = r.stderr.decode()
            assert r.returncode == 2 and f"{f}:{i + 1}:" in err, err
            assert "not a finite number" in err or "is not a number" in err, err
