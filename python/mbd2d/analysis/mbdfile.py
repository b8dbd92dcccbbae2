"""Export to the plain-text model file read by the standalone ``mbd2d-solve``.

The format is documented at the top of every file written and in
``fortran/mbd_mbdfile.f90``. Reals are written with 17 significant digits, so the file
round-trips exactly and ``mbd2d-solve`` reproduces the Python results.
"""
from __future__ import annotations

from pathlib import Path

from ..binding.pack import pack
from ..binding.tables import NCT
from ..description.builder import ModelDescription
from ..results.files import write_text
from .settings import check_solver, check_span, require_determined

HEADER = """\
# mbd2d model file, format 1 (written by `mbd2d export`; run with `mbd2d-solve FILE OUT.csv`)
# Plain text, whitespace separated. Lines starting with '#' are comments.
#   mbd2d 1                      format and version
#   name NAME                    model name
#   analysis kinematics          the analysis to run
#   t0, t_end, steps             output times t0 + k (t_end - t0) / steps, k = 0..steps
#   tol, maxit, tmin             Newton tolerance, iterations, singular-time resolution (0 = default)
#   bodies NB, then NB lines     NAME x0 y0 theta0 (rough estimates; assembly refines them)
#   constraints NC, then NC lines
#        NAME KIND BODY_I BODY_J SUB_A SUB_B OFFSET LENGTH
#        KIND: 1 revolute, 2 translational, 3 cam, 101 absolute driver,
#              102 relative-angle driver, 103 relative-distance driver
#        BODY_I, BODY_J: 1-based body numbers, 0 = ground
#        SUB_A: cam profile (1 circle, 2 spline, 3 fourier); absolute driver coordinate
#               (1 x, 2 y, 3 theta); relative-distance driver: number of its joint
#        SUB_B: cam follower (1 point, 2 roller, 3 flat)
#        OFFSET, LENGTH: the constraint's slice of the parameter list (1-based)
#   params NP, then NP reals     parameters, 4 per line, no comments inside
#        revolute       s_i(2) s_j(2)
#        translational  s_i(2) s_j(2) axis_i(2) axis_j(2)
#        cam            follower(4: point x y 0 0 | roller x y r 0 | flat x y nx ny),
#                       profile (circle cx cy R | spline n x1 y1 .. xn yn |
#                       fourier cx cy K a0 a1 b1 .. aK bK)
#        driver f(t)    np c0 .. c_{np-1} nh (A omega phase) x nh
#   end
"""


def _r(x: float) -> str:
    return f"{x:.17e}"


def export(model: ModelDescription, path: str | Path, t_end: float, steps: int, t0: float = 0.0,
           tol: float | None = None, maxit: int | None = None) -> None:
    """Write a model file for ``mbd2d-solve``.

    Raises
    ------
    ModelError
        If the model or the settings are invalid (checked as for a Python run).
    """
    t0, t_end, steps = check_span(t0, t_end, steps)
    tol_v, maxit_v = check_solver(tol, maxit)
    p = pack(model)
    require_determined(p, model)
    lines = [HEADER.rstrip("\n"), "mbd2d 1", f"name {model.name.replace(' ', '_') or 'model'}",
             "analysis kinematics", f"t0 {_r(t0)}", f"t_end {_r(t_end)}", f"steps {steps}",
             f"tol {_r(tol_v)}", f"maxit {maxit_v}", f"tmin {_r(0.0)}",
             f"bodies {p.nb}"]
    for name, b in zip(p.body_names, model.bodies):
        lines.append(f"{name} {_r(b.q0[0])} {_r(b.q0[1])} {_r(b.q0[2])}")
    lines.append(f"constraints {p.nc}")
    for k, name in enumerate(p.constraint_names):
        lines.append(f"{name} " + " ".join(str(int(v)) for v in p.ctab[:NCT - 1, k]))
    n = len(p.rpar)
    lines.append(f"params {n}")
    for i in range(0, n, 4):
        lines.append(" ".join(_r(float(v)) for v in p.rpar[i:i + 4]))
    lines.append("end")
    write_text(path, "\n".join(lines) + "\n", "export")
