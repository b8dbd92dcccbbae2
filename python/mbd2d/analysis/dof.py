"""Degrees of freedom and redundant constraints at an assembled configuration."""
from __future__ import annotations

from ..binding import core
from ..binding.pack import pack
from ..binding.status import ASSEMBLY_FAILED, INCONSISTENT, OK, error_for
from ..description.builder import ModelDescription
from ..results.dof import DofReport
from ..validate import number
from .failures import assembly_failed, inconsistent, row_names
from .settings import check_solver


def analyze_dof(model: ModelDescription, t: float = 0.0, tol: float | None = None) -> DofReport:
    """Degrees of freedom and redundant constraints at the configuration assembled from q0.

    Raises
    ------
    InconsistentConstraintsError
        If redundant constraints contradict each other (names them and gives the residual).
    AssemblyError
        If no configuration satisfies the constraints near q0.
    """
    t = number(t, "t", "analysis")
    tol_v, _ = check_solver(tol, None)
    p = pack(model)
    out = core.analyze(p, t, tol_v)
    status, worst = out.status, int(out.worst)
    if status < 0:
        raise error_for("dof", status, out.msg, entry=model.constraints[worst - 1].describe()
                        if worst else f"model {model.name!r}")
    if status == INCONSISTENT:
        raise inconsistent("dof", model, p, float(out.resid), out.dep, out.red, int(out.rank),
                           t, None)
    if status == ASSEMBLY_FAILED:
        raise assembly_failed("dof", model, float(out.resid), worst, t, None)
    if status != OK:
        raise error_for("dof", status, out.msg, t=t)
    cons, rows = row_names(p, model, out.red)
    return DofReport(model.name, t, p.nq, p.neq, int(out.rank), p.nq - int(out.rank),
                     int(out.mobility), rows, cons, out.q, list(p.coordinate_names),
                     list(p.row_labels))
