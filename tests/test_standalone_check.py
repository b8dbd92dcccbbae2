"""`check` in every front door: `mbd2d check --out`, `Model.export(analysis="check")` and
mbd2d-solve print the same report and write the same CSV.

Independent reference of the counts: the rank of J at the assembled configuration from
numpy's SVD (``numpy.linalg.matrix_rank`` of ``model.jacobian(q)``), the redundant count
neq - rank; the assembled configuration satisfies Phi = 0 (``model.phi``).
"""
from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

import mbd2d
from mbd2d.cli import main
from mbd2d.description import toml_io
from mbd2d.results import read_csv

from test_standalone import find_solver

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"


@pytest.mark.parametrize("name, t", [("fourbar_grashof", 0.0), ("fourbar_redundant", 0.25),
                                     ("door_two_hinges", 0.5), ("cam_follower", 0.1),
                                     ("parallelogram_extra_link", 0.0)])
def test_same_report_and_csv_everywhere(tmp_path: Path, capsys, name: str, t: float) -> None:
    toml = str(EX / f"{name}.toml")
    py_csv = tmp_path / "py.csv"
    assert main(["check", toml, "--t", str(t), "--out", str(py_csv)]) == 0
    py_text = capsys.readouterr().out
    mbd = tmp_path / "c.mbd"
    assert main(["export", toml, str(mbd), "--analysis", "check", "--t", str(t)]) == 0
    capsys.readouterr()
    out = tmp_path / "solve.csv"
    r = subprocess.run([find_solver(), str(mbd), str(out)], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout == py_text
    assert out.read_bytes() == py_csv.read_bytes()
    # the counts against numpy's rank of J at the assembled configuration
    model = mbd2d.load(toml)
    header, rows = read_csv(out)
    row = dict(zip(header, rows[0]))
    neq, nq = model.counts()
    q = rows[0, 1:1 + nq]
    assert np.abs(model.phi(q, t)).max() < 1e-9
    rank = np.linalg.matrix_rank(model.jacobian(q, t))
    assert (row["coordinates"], row["equations"], row["rank"]) == (nq, neq, rank)
    assert row["dof"] == nq - rank
    assert sum(v for k, v in row.items() if k.startswith("redundant.")) == neq - rank


def test_contradicting_constraints_fail_alike(tmp_path: Path, capsys) -> None:
    """A ground pivot 40 m off: the constraints contradict each other; both programs exit 4
    and name the constraints."""
    model = mbd2d.load(EX / "fourbar_seed.toml").with_params({"joint.B.points.0.0": 40.0})
    toml = tmp_path / "bad.toml"
    toml_io.dump(model, toml)
    assert main(["check", str(toml)]) == 4
    assert "contradict" in capsys.readouterr().err
    mbd = tmp_path / "c.mbd"
    model.export(mbd, analysis="check")
    r = subprocess.run([find_solver(), str(mbd), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 4 and "contradict" in r.stderr and "cannot all hold" in r.stderr
    assert not (tmp_path / "o.csv").exists()
    # the kinematics of the same file names them too (and writes the rows it has: none)
    kin = tmp_path / "k.mbd"
    model.export(kin, t_end=1.0, steps=4)
    r = subprocess.run([find_solver(), str(kin), str(tmp_path / "k.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 4 and "O2 A B O4 motor cannot all hold" in r.stderr, r.stderr


@pytest.mark.parametrize("extra, needle", [
    ("outputs multipliers", "check takes no outputs"),
    ("positions_only 1", "check takes no outputs, sensitivities, cases or positions_only"),
    ("sensitivities 1\njoint.B.points.0.0 1 9", "check takes no"),
])
def test_check_files_refuse_other_settings(tmp_path: Path, extra: str, needle: str) -> None:
    mbd = tmp_path / "c.mbd"
    mbd2d.load(EX / "fourbar_grashof.toml").export(mbd, analysis="check")
    mbd.write_text(mbd.read_text().replace("\nend\n", f"\n{extra}\nend\n"))
    r = subprocess.run([find_solver(), str(mbd), str(tmp_path / "o.csv")], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and needle in r.stderr, r.stderr


def test_export_check_refuses_what_it_cannot_hold(tmp_path: Path) -> None:
    m = mbd2d.load(EX / "fourbar_masses.toml")
    with pytest.raises(mbd2d.ModelError, match="need multipliers"):
        m.export(tmp_path / "x.mbd", analysis="check", outputs=["reactions"])
    with pytest.raises(mbd2d.ModelError, match="check computes no sensitivities"):
        m.export(tmp_path / "x.mbd", analysis="check", sensitivities=["body.crank.mass"])


def test_check_output_that_cannot_be_written(tmp_path: Path) -> None:
    mbd = tmp_path / "c.mbd"
    mbd2d.load(EX / "fourbar_grashof.toml").export(mbd, analysis="check")
    r = subprocess.run([find_solver(), str(mbd), str(tmp_path / "no" / "dir" / "o.csv")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "cannot write" in r.stderr, r.stderr
