"""Packing a model description into the flat tables the Fortran core reads (see
``fortran/mbd_model.f90``)."""
from __future__ import annotations

import numpy as np

from ..description.builder import ModelDescription
from ..description.entries import reading
from ..description.friction import FRICTION_KIND
from ..errors import ModelError
from . import core
from .status import error_for
from .tables import NCT, NFT, DynamicTables, Packed, decode


def pack(model: ModelDescription) -> Packed:
    """Flat tables of a model, checked by the core.

    Constants left open (the phase of a gear, rack or rolling disc) are set so that their
    equation holds at the q0 estimates; the core evaluates that equation.

    Raises
    ------
    ModelError
        If the model is empty, an entry's field was set to a value of the wrong form, or the
        core rejects an entry (named in the message).
    """
    with reading(model):
        return _pack(model)


def _pack(model: ModelDescription) -> Packed:
    if not model.bodies:
        raise ModelError("the model has no moving bodies; add a [[body]]", "model")
    cons = model.constraints
    if not cons and not getattr(model, "contacts", None):
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
    ctab = np.asfortranarray(np.array(cols, dtype=np.int32).reshape(-1, NCT).T)
    rp = np.array(rpar if rpar else [0.0], dtype=np.float64)
    out = core.sizes(len(model.bodies), ctab, rp)
    nq, neq, bad = int(out.nq), int(out.neq), int(out.bad)
    if out.status != 0:
        entry = cons[bad - 1].describe() if bad > 0 else "model"
        raise error_for("sizes", out.status, out.msg, entry=entry)
    q0 = np.zeros(nq)
    q0[:3 * len(model.bodies)] = np.array([b.q0 for b in model.bodies], dtype=float).ravel()
    rows = [0]
    for c in cons:
        rows.append(rows[-1] + c.nrow)
    open_phase = [k for k, c in enumerate(cons)
                  if c.phase_row is not None and getattr(c, "phase", 0.0) is None]
    if open_phase:
        phi = core.evaluate(len(model.bodies), ctab, rp, neq, q0, np.zeros(nq), 0.0).phi
        for k in open_phase:
            # the phase is the last raw parameter; Phi = g(q0) - 0 gives it
            rp[ctab[5, k] - 1 + ctab[6, k] - 1] = phi[rows[k] + cons[k].phase_row]
    names = model.coordinate_names
    owner = [k for k, c in enumerate(cons) for _ in range(c.nrow)]
    labels = [r for c in cons for r in c.rows()]
    return Packed(len(model.bodies), ctab, rp, q0, nq, neq,
                  [b.name for b in model.bodies], [c.name for c in cons],
                  [c.is_driver for c in cons], names, owner, labels)


def pack_dynamics(model: ModelDescription, p: Packed) -> DynamicTables:
    """Masses (2, nb), gravity, the force table (NFT, nf), force parameters and v0 (nq).
    The force elements are the forces, the contacts and the joint frictions
    (``model.force_elements()``).

    Raises
    ------
    ModelError
        If a body has no mass or inertia, or an entry's field has the wrong form.
    """
    with reading(model):
        return _pack_dynamics(model, p)


def _pack_dynamics(model: ModelDescription, p: Packed) -> DynamicTables:
    bmass = np.zeros((2, len(model.bodies)), order="F")
    for i, b in enumerate(model.bodies):
        if b.mass is None or b.inertia is None:
            raise ModelError("dynamics needs 'mass' and 'inertia' for every body (inertia about "
                             "the centre of mass; 0 for a point mass)", f"body '{b.name}'")
        bmass[:, i] = (b.mass, b.inertia)
    body_idx = {b.name: i + 1 for i, b in enumerate(model.bodies)}
    body_idx["ground"] = 0
    cols: list[list[int]] = []
    fpar: list[float] = []
    joint_idx = {j.name: k + 1 for k, j in enumerate(model.joints)}
    for _, what, e in model.force_elements():
        if what == "friction":
            raw = e.friction.raw()
            cols.append([FRICTION_KIND, body_idx[e.bodies[0]], body_idx[e.bodies[1]],
                         len(fpar) + 1, len(raw), joint_idx[e.name]])
        else:
            raw = e.raw()
            cols.append([e.kind, body_idx[e.bodies[0]], body_idx[e.bodies[1]], len(fpar) + 1,
                         len(raw), 0])
        fpar.extend(raw)
    ftab = np.asfortranarray(np.array(cols, dtype=np.int32).reshape(-1, NFT).T)
    fp = np.array(fpar if fpar else [0.0])
    v0 = np.zeros(p.nq)
    v0[:3 * p.nb] = np.array([b.v0 for b in model.bodies], dtype=float).ravel()
    return DynamicTables(bmass, np.asarray(model.gravity, dtype=float), ftab, fp, v0)


__all__ = ["NCT", "Packed", "DynamicTables", "decode", "pack", "pack_dynamics"]
