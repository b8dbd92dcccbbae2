"""Instructions per kinematic step (callgrind): stable figures on a shared machine.

The four-bar (examples/fourbar_grashof.toml, 1 rev/s) runs its kinematic analysis in the core
twice, n1 and n2 output steps of size h, under ``valgrind --tool=callgrind`` with collection
switched on only inside the core's time loop (``kin_run``) and a profile dumped after each
run. Instructions per step = (I(n2) - I(n1)) / (n2 - n1): the setup (model, assembly, column
scale) cancels. The same difference, taken per function (inclusive), splits a step into its
parts (assembly, LU, triangular solves, the rest of the loop).

Skipped (``{"available": False, "reason"}``) when valgrind is not installed.

    python bench/callgrind.py [--h 1e-3 1e-4] [--model fourbar_grashof] [--parts]
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

BENCH = Path(__file__).resolve().parent
EX = BENCH.parent / "examples"
H_VALUES = (1e-3, 1e-4)
STEPS = (1000, 3000)          # n1, n2
LOOP_FN = "__mbd_kinematics_MOD_kin_run"
#: the parts of a step: each function's own instructions (exclusive, callgrind's "self")
#: go to the first part with a pattern matching its name; what no pattern claims is "loop"
#: (the time loop: predictor, step acceptance, checks, output). Library functions are
#: matched by name as well (sincos is the assembly's, the LAPACK routines the LU's or the
#: solves').
PARTS = {
    "assembly": (r"assemble", r"scatter_", r"asm_turn", r"con_eval", r"_eval\b",
                 r"point_terms", r"put_", r"sincos", r"\bsin\b", r"\bcos\b", r"mbd_joint_",
                 r"mbd_points_", r"mbd_drivers_", r"mbd_functions_"),
    "LU": (r"_MOD_factor\b", r"sparse_factor", r"splu_factor", r"factor_kernel", r"lu_factor",
           r"lu_det_sign", r"dgetf2", r"dgetrf", r"dgecon", r"dlaswp", r"idamax", r"dger_",
           r"dscal", r"dlacn2", r"dlatrs"),
    "solves": (r"_MOD_solve", r"splu_solve", r"solve2?_kernel", r"lu_solve", r"dtrsv",
               r"dtrsm", r"dgetrs"),
}

WORKER = r"""
import sys
import numpy as np
import mbd2d
from mbd2d import _core
from mbd2d.binding.pack import pack
path, h, n1, n2 = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
pos = int(sys.argv[5]) if len(sys.argv) > 5 else 0     # 1: positions only
p = pack(mbd2d.load(path))
for n in (n1, n2):
    out = _core.core_kinematics(p.nb, p.ctab, p.rpar, p.neq, p.q0, 0.0, n * h, n, 0.0, 0,
                                0.0, 1, 0, n + 1, pos, 0 if pos else n + 1,
                                np.zeros(2, dtype=np.int32))
    assert out[-2] == 0, out[-1]
    print("COUNTS", n, int(out[3][5]), int(out[3][6]), flush=True)
"""


def available() -> tuple[bool, str]:
    """Whether valgrind can be run: (True, version) or (False, the reason)."""
    exe = shutil.which("valgrind")
    if exe is None:
        return False, "valgrind is not installed (apt-get install valgrind)"
    try:
        v = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.SubprocessError) as e:
        return False, f"valgrind does not run: {e}"
    return True, v.stdout.strip()


def _totals(path: Path) -> int:
    """Total instructions (Ir) of one callgrind dump."""
    for line in path.read_text(encoding="utf-8", errors="replace").splitlines():
        if line.startswith(("summary:", "totals:")):
            return int(line.split()[1])
    return 0


def _exclusive(path: Path) -> dict[str, int]:
    """Own (exclusive) instructions per function of one dump (callgrind_annotate)."""
    exe = shutil.which("callgrind_annotate")
    if exe is None:
        return {}
    out = subprocess.run([exe, "--inclusive=no", "--threshold=100", str(path)],
                         capture_output=True, text=True, timeout=120).stdout
    fns: dict[str, int] = {}
    for line in out.splitlines():
        m = re.match(r"\s*([\d,]+)\s+(?:\([^)]*\)\s+)?(\S.*?):(\S+)", line)
        if m:
            name = m.group(3).split(" ")[0]
            fns[name] = fns.get(name, 0) + int(m.group(1).replace(",", ""))
    return fns


def _parts(d1: dict[str, int], d2: dict[str, int], steps: int, total: float) -> dict[str, float]:
    """Instructions per step of each part, from the exclusive counts of the two dumps.

    Each function's own instructions count once, towards the first part whose pattern its
    name matches (PARTS); the rest of the step is "loop".
    """
    per = {k: (d2.get(k, 0) - d1.get(k, 0)) / steps for k in set(d1) | set(d2)}
    out = {name: 0.0 for name in PARTS}
    for f, v in per.items():
        for name, pats in PARTS.items():
            if any(re.search(p, f) for p in pats):
                out[name] += v
                break
    out["loop"] = total - sum(out.values())
    return out


def measure(stem: str = "fourbar_grashof", h: float = 1e-3, steps: tuple[int, int] = STEPS,
            parts: bool = True, positions_only: bool = False) -> dict[str, Any]:
    """Instructions per step of the kinematic loop at step size h (see the module docstring).

    Parameters
    ----------
    stem : str
        Example model (examples/<stem>.toml).
    h : float
        Output step size (s).
    steps : tuple of int
        The two run lengths n1 < n2.
    parts : bool
        Also split a step into assembly, LU, solves and the rest (needs callgrind_annotate).
    positions_only : bool
        The positions-only kinematics (chord steps) instead of the full step.

    Returns
    -------
    dict
        {"h", "positions_only", "steps", "instructions_per_step",
        "newton_corrections_per_step", "lu_per_step", "parts" (instructions per step of each
        part)}.
    """
    n1, n2 = steps
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cg.out"
        cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
               f"--toggle-collect={LOOP_FN}", f"--dump-after={LOOP_FN}",
               sys.executable, "-c", WORKER, str(EX / f"{stem}.toml"), repr(h), str(n1),
               str(n2), str(int(positions_only))]
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
        r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=1800)
        if r.returncode != 0:
            raise RuntimeError(f"callgrind run failed ({r.returncode}): {r.stderr[-2000:]}")
        counts = [line.split()[1:] for line in r.stdout.splitlines()
                  if line.startswith("COUNTS")]
        dumps = sorted(Path(tmp).glob("cg.out.*"), key=lambda p: int(p.suffix[1:]))
        if len(dumps) < 2:
            raise RuntimeError(f"expected two callgrind dumps, found {len(dumps)}")
        d1, d2 = dumps[-2], dumps[-1]
        per_step = (_totals(d2) - _totals(d1)) / (n2 - n1)
        res: dict[str, Any] = {"model": f"examples/{stem}.toml", "h": h,
                               "positions_only": positions_only, "steps": [n1, n2],
                               "instructions_per_step": per_step}
        if len(counts) == 2:
            (_, c1, l1), (_, c2, l2) = counts
            res["newton_corrections_per_step"] = (int(c2) - int(c1)) / (n2 - n1)
            res["lu_per_step"] = (int(l2) - int(l1)) / (n2 - n1)
        if parts:
            res["parts"] = _parts(_exclusive(d1), _exclusive(d2), n2 - n1, per_step)
    return res


def callgrind(h_values: tuple[float, ...] = H_VALUES, stem: str = "fourbar_grashof",
              log: bool = True, positions: bool = True) -> dict[str, Any]:
    """measure() at each step size (the full step, then with positions the positions-only
    step), or the reason it was skipped."""
    ok, info = available()
    if not ok:
        if log:
            print(f" callgrind skipped: {info}", flush=True)
        return {"available": False, "reason": info}
    rows = []
    for pos, h in [(False, h) for h in h_values] + [(True, h) for h in h_values if positions]:
        r = measure(stem, h, positions_only=pos)
        rows.append(r)
        if log:
            parts = r.get("parts", {})
            txt = ", ".join(f"{k} {v:.0f}" for k, v in parts.items())
            print(f"  h = {h:g}{' positions only' if pos else ''}: "
                  f"{r['instructions_per_step']:.0f} instructions/step "
                  f"({r.get('newton_corrections_per_step', 0):.2f} Newton corrections, "
                  f"{r.get('lu_per_step', 0):.2f} LU per step; {txt})", flush=True)
    return {"available": True, "valgrind": info, "rows": rows}


def main() -> dict[str, Any]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--h", type=float, nargs="*", default=list(H_VALUES))
    ap.add_argument("--model", default="fourbar_grashof")
    return callgrind(tuple(ap.parse_args().h), ap.parse_args().model)


if __name__ == "__main__":
    print(json.dumps(main(), indent=1))
