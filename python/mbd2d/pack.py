"""Packing a model into the flat tables the Fortran core reads (see mbd_model.f90)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from . import _core
from .errors import ModelError

if TYPE_CHECKING:  # pragma: no cover
    from .model import Model

NCT = 8  # rows of the constraint table


@dataclass
class Packed:
    """A model as flat tables, with the names that go with them."""

    nb: int
    ctab: np.ndarray            # int32 (NCT, nc), Fortran order
    rpar: np.ndarray            # float64
    q0: np.ndarray              # float64 (nq,), extras zero (the core estimates them)
    nq: int
    neq: int
    body_names: list[str]
    constraint_names: list[str]
    driver_flags: list[bool]
    coordinate_names: list[str]
    row_owner: list[int] = field(default_factory=list)   # constraint index of each row
    row_labels: list[str] = field(default_factory=list)

    @property
    def nc(self) -> int:
        return self.ctab.shape[1]


def decode(raw: bytes | str) -> str:
    """A Fortran message as text."""
    if isinstance(raw, bytes):
        raw = raw.decode("utf-8", "replace")
    return raw.strip()


def pack(model: "Model") -> Packed:
    """Flat tables of a model, checked by the core.

    Constants left open (the phase of a gear, rack or rolling disc) are set so that their
    equation holds at the q0 estimates; the core evaluates that equation.

    Raises
    ------
    ModelError
        If the model is empty or the core rejects an entry (named in the message).
    """
    if not model.bodies:
        raise ModelError("the model has no moving bodies; add a [[body]]", "model")
    cons = model.constraints
    if not cons:
        raise ModelError("the model has no joints or drivers; add a [[joint]] or [[driver]]",
                         "model")
    body_idx = {b.name: i + 1 for i, b in enumerate(model.bodies)}
    body_idx["ground"] = 0
    con_idx = {c.name: k + 1 for k, c in enumerate(cons)}
    cols: list[list[int]] = []
    rpar: list[float] = []
    q0_by_name = {b.name: b.q0 for b in model.bodies}
    q0_by_name["ground"] = (0.0, 0.0, 0.0)
    for c in cons:
        params = c.raw_in(cons, q0_by_name)
        suba, subb = c.subkinds(body_idx.__getitem__, con_idx.__getitem__)
        cols.append([c.kind, body_idx[c.bodies[0]], body_idx[c.bodies[1]], suba, subb,
                     len(rpar) + 1, len(params), 0])
        rpar.extend(params)
    ctab = np.asfortranarray(np.array(cols, dtype=np.int32).T)
    rp = np.array(rpar if rpar else [0.0], dtype=np.float64)
    nq, neq, status, msg, bad = _core.core_sizes(len(model.bodies), ctab, rp)
    if status != 0:
        entry = cons[bad - 1].describe() if bad > 0 else "model"
        raise ModelError(decode(msg), entry)
    q0 = np.zeros(nq)
    q0[:3 * len(model.bodies)] = np.array([b.q0 for b in model.bodies], dtype=float).ravel()
    rows = [0]
    for c in cons:
        rows.append(rows[-1] + c.nrow)
    open_phase = [k for k, c in enumerate(cons)
                  if c.phase_row is not None and getattr(c, "phase", 0.0) is None]
    if open_phase:
        phi = _core.core_eval(len(model.bodies), ctab, rp, neq, q0, np.zeros(nq), 0.0)[0]
        for k in open_phase:
            # the phase is the last raw parameter; Phi = g(q0) - 0 gives it
            rp[ctab[5, k] - 1 + ctab[6, k] - 1] = phi[rows[k] + cons[k].phase_row]
    names = [f"{b.name}.{s}" for b in model.bodies for s in ("x", "y", "theta")]
    names += [n for c in cons for n in c.extra_names()]
    owner = [k for k, c in enumerate(cons) for _ in range(c.nrow)]
    labels = [r for c in cons for r in c.rows()]
    return Packed(len(model.bodies), ctab, rp, q0, int(nq), int(neq),
                  [b.name for b in model.bodies], [c.name for c in cons],
                  [c.is_driver for c in cons], names, owner, labels)
