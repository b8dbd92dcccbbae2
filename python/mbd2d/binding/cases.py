"""The per-case tables of a batch (design sweeps): which entries of the core's flat tables
each case sets, to what, and which phases the core sets again from the q0 estimates.

A design parameter is one entry of a flat table (:mod:`mbd2d.binding.params`), so a case
mostly sets the swept parameters' own entries. Two things packing computes from several
numbers are kept exact as well:

* constraints whose raw parameters packing derives from other entries (a gear's centres
  from the revolutes of its gears, its phase from the q0 estimates when left open): their
  raw parameters are computed here per case, from the case's constraints, exactly as
  packing computes them, and set whole;
* phases left open on a rack-pinion or rolling disc: packing takes them from the phase row
  of Phi at the q0 estimates, so the core does the same per case (``opens``).

Everything else the core derives from the raw numbers (the length scale, unit axes, spline
coefficients, gear geometry) it rebuilds per case, so a case gives what packing its own
model gives, bit for bit.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..description.builder import ModelDescription
from ..description.joints import Constraint
from ..description.parameters import Parameter, constraints_with
from .params import parameter_table
from .tables import DynamicTables, Packed


@dataclass
class CaseTables:
    """vtab (2, nv) int32: (table, 1-based index) of each value row; vals (nv, ncase)
    float64, one column per case; opens (2, no) int32: (rpar index, row of Phi) of each
    open phase the core sets again; all Fortran-ordered."""

    vtab: np.ndarray
    vals: np.ndarray
    opens: np.ndarray


def _derived(c: Constraint) -> bool:
    """Packing derives the constraint's raw parameters from more than its own numbers."""
    return type(c).raw_in is not Constraint.raw_in


def case_tables(model: ModelDescription, p: Packed, d: DynamicTables | None,
                params: Sequence[Parameter], values: np.ndarray) -> CaseTables:
    """The tables for the cases values (n_params, ncase) of params.

    Without dynamics tables (``d`` None: a kinematic run) only the constraints' entries are
    set; masses, gravity and forces do not enter a kinematic run.
    """
    values = np.asarray(values, dtype=np.float64).reshape(len(params), -1)
    ptab = parameter_table(p, params, d)
    keep = [k for k, prm in enumerate(params) if d is not None or prm.table == "constraint"]
    cols = [ptab[:, k] for k in keep]
    rows = [values[k] for k in keep]
    cons = model.constraints
    joint_params = [k for k, prm in enumerate(params) if prm.table == "constraint"]
    derived = [k for k, c in enumerate(cons) if _derived(c)] if joint_params else []
    if derived:
        q0 = {b.name: b.q0 for b in model.bodies}
        q0["ground"] = (0.0, 0.0, 0.0)
        chosen = [params[k] for k in joint_params]
        raw = np.array([_derived_raw(model, chosen, values[joint_params, j], derived, q0)
                        for j in range(values.shape[1])]).reshape(values.shape[1], -1)
        for k in derived:
            off, n = int(p.ctab[5, k]), int(p.ctab[6, k])
            cols += [np.array([1, off + i], dtype=np.int32) for i in range(n)]
        rows += list(raw.T)
    if not cols:
        # no swept number enters this analysis (gravity in kinematics): every case is the base
        # model; f2py takes no zero-length table, so the first raw parameter is set to itself
        cols = [np.array([1, 1], dtype=np.int32)]
        rows = [np.full(values.shape[1], p.rpar[0])]
    vtab = np.asfortranarray(np.array(cols, dtype=np.int32).reshape(-1, 2).T)
    vals = np.asfortranarray(np.array(rows, dtype=np.float64).reshape(len(cols), values.shape[1]))
    return CaseTables(vtab, vals, open_phases(model, p, params))


def _derived_raw(model: ModelDescription, chosen: list[Parameter], values: np.ndarray,
                 derived: list[int], q0: dict[str, Any]) -> list[float]:
    """The raw parameters of the derived constraints for one case, as packing gives them."""
    cm = constraints_with(model, chosen, values)
    return [float(v) for k in derived for v in cm[k].raw_in(cm, q0)]


def open_phases(model: ModelDescription, p: Packed, params: Sequence[Parameter]) -> np.ndarray:
    """(rpar index, row of Phi), both 1-based, of each phase left open that a swept
    parameter changes (a swept phase is no longer open); int32 (2, no)."""
    cons = model.constraints
    rows = np.cumsum([0] + [c.nrow for c in cons])
    touched = {prm.element for prm in params if prm.table == "constraint"}
    given = {prm.element for prm in params if prm.table == "constraint" and prm.field == "phase"}
    out = []
    for k, c in enumerate(cons):
        if c.phase_row is None or getattr(c, "phase", 0.0) is not None:
            continue
        if k in touched and k not in given:
            out.append([int(p.ctab[5, k]) + int(p.ctab[6, k]) - 1, int(rows[k]) + c.phase_row + 1])
    return np.asfortranarray(np.array(out, dtype=np.int32).reshape(-1, 2).T)


__all__ = ["CaseTables", "case_tables", "open_phases"]
