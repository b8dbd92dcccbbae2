"""Packing a model into the flat tables the Fortran core reads (see mbd_model.f90)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from . import _core
from .errors import ModelError
from .model import (COORDINATES, DRV_ABS, DRV_REL_ANGLE, DRV_REL_DIST, Cam, Driver)

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
    joint_idx = {c.name: k + 1 for k, c in enumerate(cons)}
    cols: list[list[int]] = []
    rpar: list[float] = []
    for c in cons:
        bi, bj = body_idx[c.bodies[0]], body_idx[c.bodies[1]]
        if isinstance(c, Driver):
            params = c.f.encode()
            if c.driver_type == "absolute":
                kind, suba, subb = DRV_ABS, COORDINATES[c.coordinate], 0
            elif c.driver_type == "relative-angle":
                kind, suba, subb = DRV_REL_ANGLE, 0, 0
            else:
                kind, suba, subb = DRV_REL_DIST, joint_idx[c.joint], 0  # type: ignore[index]
        else:
            kind, suba, subb, params = c.pack()  # type: ignore[attr-defined]
        cols.append([kind, bi, bj, suba, subb, len(rpar) + 1, len(params), 0])
        rpar.extend(params)
    ctab = np.asfortranarray(np.array(cols, dtype=np.int32).T)
    rp = np.ascontiguousarray(rpar, dtype=np.float64)
    if rp.size == 0:
        rp = np.zeros(1)
    nq, neq, status, msg, bad = _core.core_sizes(len(model.bodies), ctab, rp)
    if status != 0:
        entry = cons[bad - 1].describe() if bad > 0 else "model"
        raise ModelError(decode(msg), entry)
    names = [f"{b.name}.{s}" for b in model.bodies for s in ("x", "y", "theta")]
    names += [f"{c.name}.alpha" for c in cons if isinstance(c, Cam)]
    q0 = np.zeros(nq)
    q0[:3 * len(model.bodies)] = np.array([b.q0 for b in model.bodies], dtype=float).ravel()
    owner = [k for k, c in enumerate(cons) for _ in range(c.nrow)]
    return Packed(len(model.bodies), ctab, rp, q0, int(nq), int(neq),
                  [b.name for b in model.bodies], [c.name for c in cons],
                  [isinstance(c, Driver) for c in cons], names, owner)
