"""The standalone executable mbd2d-solve reproduces the Python path from an exported file."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d.results import read_csv

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"


def find_solver() -> str:
    """mbd2d-solve from PATH, next to this Python, or a build directory of the checkout."""
    candidates = [shutil.which("mbd2d-solve"), str(Path(sys.executable).parent / "mbd2d-solve")]
    candidates += [str(p) for p in sorted(ROOT.glob("build*/mbd2d-solve"))]
    for c in candidates:
        if c and os.access(c, os.X_OK):
            return c
    raise AssertionError("mbd2d-solve not found: `pip install .` installs it next to `mbd2d`")


@pytest.fixture(scope="module")
def solver() -> str:
    return find_solver()


@pytest.mark.parametrize("name", ["fourbar_grashof", "slider_crank", "cam_follower"])
def test_matches_python(tmp_path: Path, solver: str, name: str) -> None:
    model = mbd2d.load(EX / f"{name}.toml")
    mbd = tmp_path / f"{name}.mbd"
    model.export(mbd, t_end=1.0, steps=200)
    out = tmp_path / "fortran.csv"
    r = subprocess.run([solver, str(mbd), str(out)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    res = model.kinematics(t_end=1.0, steps=200)
    py = tmp_path / "python.csv"
    res.to_csv(py)
    hf, rf = read_csv(out)
    hp, rp = read_csv(py)
    assert hf == hp
    assert rf.shape == rp.shape == (201, 1 + 9 * len(model.bodies))
    np.testing.assert_allclose(rf, rp, rtol=0, atol=1e-12)


def test_toggle_partial_output(tmp_path: Path, solver: str) -> None:
    model = mbd2d.load(EX / "fourbar_seed.toml")
    mbd = tmp_path / "seed.mbd"
    model.export(mbd, t_end=1.0, steps=1000)
    out = tmp_path / "seed.csv"
    r = subprocess.run([solver, str(mbd), str(out)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 3
    assert "Singular configuration (dead centre) at t = 0.88591864" in r.stderr
    assert '"motor"' in r.stderr
    _, rows = read_csv(out)
    with pytest.raises(mbd2d.SingularConfigurationError) as err:
        model.kinematics(t_end=1.0, steps=1000)
    res = err.value.results
    assert rows.shape[0] == len(res.t) == 886
    np.testing.assert_allclose(rows[:, 1:4], res.q[:, 0:3], rtol=0, atol=1e-12)


def test_file_is_documented(tmp_path: Path) -> None:
    mbd = tmp_path / "m.mbd"
    mbd2d.load(EX / "cam_follower.toml").export(mbd, t_end=1.0, steps=10)
    text = mbd.read_text()
    assert text.startswith("# mbd2d model file, format 1")
    for key in ("bodies", "constraints", "params", "KIND: 1 revolute", "end"):
        assert key in text


@pytest.mark.parametrize("content, needle", [
    ("hello\n", "not an mbd2d model file"),
    ("mbd2d 1\nbodies 1\nb 0 0 0\nconstraints 1\nc 999 1 0 0 0 1 0\nparams 0\nend\n",
     "unknown constraint kind"),
    ("mbd2d 1\nbodies 1\nb 0 0\n", "bad body line"),
    ("mbd2d 1\nbodies 1\nb 0 0 0\n", 'missing "end"'),
])
def test_bad_files(tmp_path: Path, solver: str, content: str, needle: str) -> None:
    f = tmp_path / "bad.mbd"
    f.write_text(content)
    r = subprocess.run([solver, str(f), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2
    assert needle in r.stderr


def test_missing_file(tmp_path: Path, solver: str) -> None:
    r = subprocess.run([solver, str(tmp_path / "none.mbd"), str(tmp_path / "o.csv")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "cannot open" in r.stderr
